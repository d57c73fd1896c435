//! Scratch space of the block loops as an explicit workspace owned by the caller: one entry per
//! chunk of a threaded loop, so that the loops need no thread-local or shared mutable state and,
//! once the entries have grown to their sizes, allocate nothing.
//!
//! A threaded loop splits its items (blocks of [`crate::biot_savart::LANES`] points) into at most
//! `threads × per_thread` contiguous chunks and hands each chunk its own entry; rayon balances
//! the chunks over its threads. Every item is computed by the same code whichever chunk holds it
//! and the scratch is fully overwritten before it is read, so the results do not depend on the
//! chunking: a threaded loop is bit-identical to the serial one.

use rayon::prelude::*;

/// Chunks per rayon thread of the direct Biot–Savart loops (uniform work per block; each entry
/// holds a [`crate::biot_savart::NodeBlock`] as large as the filament set, so few).
pub(crate) const DIRECT_CHUNKS_PER_THREAD: usize = 2;

/// Chunks per rayon thread of the treecode's loop (the work per block varies with the points'
/// distance from the wake; the entries are small).
pub(crate) const TREE_CHUNKS_PER_THREAD: usize = 8;

/// Scratch entries of type `S`, one per chunk of a threaded loop (the first also serves the
/// serial loops).
#[derive(Debug, Clone, Default)]
pub(crate) struct ScratchPool<S> {
    entries: Vec<S>,
}

impl<S: Default + Send> ScratchPool<S> {
    /// The first entry, for a serial loop (created on first use).
    pub(crate) fn first(&mut self) -> &mut S {
        if self.entries.is_empty() {
            self.entries.push(S::default());
        }
        &mut self.entries[0]
    }

    /// The entries created so far.
    pub(crate) fn entries(&self) -> &[S] {
        &self.entries
    }

    /// The entries created so far, mutably.
    pub(crate) fn entries_mut(&mut self) -> &mut [S] {
        &mut self.entries
    }

    /// Run `f(first_item, items, scratch)` on rayon over `data`, split into items of `item_len`
    /// elements (the last may be shorter) and the items into at most
    /// `rayon::current_num_threads() × per_thread` contiguous chunks, each with its own entry.
    /// `first_item` is the index of the chunk's first item. Allocates only to create entries.
    ///
    /// # Panics
    /// If `item_len == 0`.
    pub(crate) fn for_each_chunk<T: Send>(
        &mut self,
        data: &mut [T],
        item_len: usize,
        per_thread: usize,
        f: impl Fn(usize, &mut [T], &mut S) + Sync,
    ) {
        assert!(item_len > 0, "ScratchPool::for_each_chunk: item length");
        let n_items = data.len().div_ceil(item_len);
        if n_items == 0 {
            return;
        }
        let want = (rayon::current_num_threads() * per_thread).clamp(1, n_items);
        let per_chunk = n_items.div_ceil(want);
        let n_chunks = n_items.div_ceil(per_chunk);
        if self.entries.len() < n_chunks {
            self.entries.resize_with(n_chunks, S::default);
        }
        data.par_chunks_mut(per_chunk * item_len)
            .zip(self.entries[..n_chunks].par_iter_mut())
            .enumerate()
            .for_each(|(c, (chunk, scratch))| f(c * per_chunk, chunk, scratch));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every item is visited once with its index, whatever the number of threads, and the
    /// entries are reused (no new entry on a second pass).
    #[test]
    fn chunks_cover_every_item_once() {
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                for (n, item_len) in [(0usize, 4usize), (1, 4), (7, 4), (8, 4), (101, 8), (1000, 3)] {
                    let mut data = vec![usize::MAX; n];
                    let mut scratch = ScratchPool::<Vec<usize>>::default();
                    for _ in 0..2 {
                        scratch.for_each_chunk(&mut data, item_len, 2, |first, items, seen| {
                            for (i, item) in items.chunks_mut(item_len).enumerate() {
                                seen.push(first + i);
                                for (k, x) in item.iter_mut().enumerate() {
                                    *x = (first + i) * item_len + k;
                                }
                            }
                        });
                    }
                    assert!(data.iter().enumerate().all(|(k, &x)| x == k), "n {n}, threads {threads}");
                    let n_items = n.div_ceil(item_len);
                    assert!(scratch.entries().len() <= (2 * threads).min(n_items.max(1)));
                    let mut seen: Vec<usize> = scratch.entries().iter().flatten().copied().collect();
                    seen.sort_unstable();
                    let twice: Vec<usize> = (0..n_items).flat_map(|i| [i, i]).collect();
                    assert_eq!(seen, twice, "n {n}, threads {threads}");
                }
            });
        }
    }
}
