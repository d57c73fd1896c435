//! A wake filament set's induction at many points: summed directly, or through a treecode
//! (treecode.rs) that is either built for the set at hand or, for the far wake of a wake that
//! only translates, kept across time steps (docs/uvlm.md §14).
//!
//! **Persistence.** A prescribed wake in a uniform stream moves rigidly: every step adds the same
//! displacement `d` to every node. A cluster's moments about a centre that moves with it do not
//! change, so a tree built at step `n₀` holds at step `n` the wake of step `n₀` translated by
//! `D = Σ d`, and its induction at `P` is the tree's at `P − D`. Between `n₀` and `n` the far
//! wake changes only at its two ends:
//! - new rows enter it behind the trailing edge: those segments are summed directly (they are
//!   the rows nearest the lattice, which a tree sums directly anyway);
//! - the oldest rows leave it when the ring buffer is full, and the last row's spanwise edge
//!   changes strength: the tree takes the new strengths (0 for a segment that left) through
//!   [`Treecode::set_segments`], which updates the moments exactly and keeps the error bound.
//!
//! Segments are matched through their [`SegmentKeys`](crate::aic::SegmentKeys) (surface, push number of the row, kind,
//! strip, image copy), which ascend in the set's order, so one merge of the two key lists finds
//! what changed. The tree is rebuilt every [`REBUILD_PERIOD`] steps, when the wake did not move
//! rigidly ([`WakeTree::break_persistence`]), and when most of the set is new.

use crate::aic::{FarRows, SegmentKeys};
use crate::biot_savart::{Filaments, LANES, NodeBlock, fill_block, load_lanes, velocity_block};
use crate::induce::{Points, induced_velocity_inplace};
use crate::mixed::{MixedScratch, add_velocity_mixed};
use crate::params::{Parallel, WakeAggregation};
use crate::scratch::ScratchPool;
use crate::treecode::{Treecode, block_order};

/// Steps between rebuilds of a persistent tree: the rows shed since the build are summed
/// directly, so a longer period trades build time for direct sums.
pub(crate) const REBUILD_PERIOD: usize = 32;

/// A tree built for one set (not kept across steps) applies from this many times the
/// aggregation's `min_segments`: on the paper's wing it breaks even at about twice the wake of a
/// kept tree (docs/uvlm.md §14).
pub(crate) const REBUILT_FACTOR: usize = 2;

/// A wake filament set's induction: direct, or through a treecode built once per set or kept
/// across steps.
#[derive(Debug)]
pub(crate) struct WakeTree {
    settings: WakeAggregation,
    tree: Treecode,
    /// Whether `tree` holds the current set (built for it, or synchronised with it).
    ready: bool,
    order: Vec<u32>,
    stack: Vec<(usize, usize)>,
    persist: Persist,
    /// The workspace of the mixed-precision direct sum, when this tree's set may use it.
    mixed: Option<MixedScratch>,
    /// Whether the last sync saw part of the set only ([`WakeTree::sync_rows`]): the tree
    /// applies whatever that part's size.
    partial: bool,
}

/// The state of a tree kept across steps.
#[derive(Debug, Default)]
struct Persist {
    /// Whether the tree holds the set of its build translated by `shift`, with its segments
    /// named by `keys`.
    valid: bool,
    keys: Vec<u64>,
    /// The tree's segments' strengths and core constants, in build order (compared with the
    /// set's in order, which is cheaper than reading the leaves).
    held: Vec<[f64; 3]>,
    /// Displacement of the wake since the build, m.
    shift: [f64; 3],
    /// Steps since the build.
    age: usize,
    /// The current set's segments the tree does not hold and its legs: summed directly.
    direct: Filaments,
    /// The points moved by `−shift`.
    shifted: Points,
    /// The held segments whose strength or core changed: `(segment, g, core2, cut2)`.
    changes: Vec<(u32, f64, f64, f64)>,
}

impl WakeTree {
    /// A tree whose set is summed with the f64 kernel where the treecode does not apply.
    pub(crate) fn new(settings: &WakeAggregation) -> Self {
        Self::with_mixed(settings, false)
    }

    /// A tree for the far wake: where the treecode does not apply, its set is summed in mixed
    /// precision when the settings ask for it (mixed.rs).
    pub(crate) fn far(settings: &WakeAggregation) -> Self {
        Self::with_mixed(settings, settings.enabled && settings.mixed_precision)
    }

    fn with_mixed(settings: &WakeAggregation, mixed: bool) -> Self {
        let mut tree =
            if settings.enabled { Treecode::new(settings.order, settings.leaf_size) } else { Treecode::default() };
        tree.set_mixed(mixed);
        Self {
            settings: *settings,
            tree,
            ready: false,
            order: Vec::new(),
            stack: Vec::new(),
            persist: Persist::default(),
            mixed: mixed.then(MixedScratch::default),
            partial: false,
        }
    }

    /// The set changed in a way the tree cannot follow: rebuild at the next use.
    pub(crate) fn invalidate(&mut self) {
        self.forget_mixed();
        self.ready = false;
        self.persist.valid = false;
        self.partial = false;
    }

    /// The wake moved other than rigidly (or was replaced): the next [`WakeTree::sync`] rebuilds.
    pub(crate) fn break_persistence(&mut self) {
        self.forget_mixed();
        self.persist.valid = false;
    }

    /// The set changed: the mixed-precision sum loads its constants again.
    fn forget_mixed(&mut self) {
        if let Some(m) = &mut self.mixed {
            m.forget();
        }
    }

    /// Every node of the set's wake moved by `d`, m (a rigid convection step).
    pub(crate) fn translate(&mut self, d: [f64; 3]) {
        let p = &mut self.persist;
        for q in 0..3 {
            p.shift[q] += d[q];
        }
        p.age += 1;
    }

    pub(crate) fn applies(&self, set: &Filaments) -> bool {
        self.partial || self.settings.applies(set.n_segments())
    }

    /// Whether `set`'s induction comes from the crate's f64 kernel throughout (not from a
    /// treecode's expansions, nor from the mixed-precision kernel's regular forms).
    pub(crate) fn kernel_exact(&self, set: &Filaments) -> bool {
        self.mixed.is_none() && !self.applies(set)
    }

    /// The node rows of a wake of `len` rows the next [`WakeTree::sync_rows`] needs, when the
    /// tree is kept and will be updated in place: the rows shed since its build (`1..=age + 1`,
    /// whose segments it does not hold) and the last (`len`, whose edge changes strength as the
    /// buffer drops rows). The rows between are the tree's, translated and unchanged. `None`
    /// when the next sync rebuilds, or when nothing would be left out.
    pub(crate) fn rows_needed(&self, len: usize) -> Option<FarRows> {
        let (head, tail) = (self.persist.age + 1, len);
        (self.updatable() && head + 2 < tail).then_some((head, tail))
    }

    /// Whether the next sync may update the kept tree in place rather than rebuild it.
    fn updatable(&self) -> bool {
        self.ready && self.persist.valid && self.persist.age < REBUILD_PERIOD
    }

    /// Make the tree hold `set`, whose segments are named by `keys` (or `None` when they cannot
    /// be): update the persistent tree when it is valid, young and holds most of the set,
    /// else rebuild it.
    pub(crate) fn sync(&mut self, set: &Filaments, keys: Option<&[u64]>) {
        self.forget_mixed();
        let Some(keys) = keys.filter(|k| k.len() == set.n_segments() && self.applies(set)) else {
            self.invalidate();
            return;
        };
        debug_assert!(keys.windows(2).all(|w| w[0] < w[1]), "segment keys ascend");
        self.partial = false;
        if self.updatable() && self.update(set, keys, None) {
            return;
        }
        self.tree.build(set);
        self.tree.drop_legs();
        let p = &mut self.persist;
        p.keys.clear();
        p.keys.extend_from_slice(keys);
        p.held.clear();
        p.held.extend((0..set.n_segments()).map(|s| [set.seg_g[s], set.seg_core2[s], set.seg_cut2[s]]));
        p.shift = [0.0; 3];
        p.age = 0;
        p.valid = true;
        p.direct.clear();
        copy_legs(set, &mut p.direct);
        self.ready = true;
    }

    /// Update the kept tree from part of the set: `set` holds the node rows of
    /// [`WakeTree::rows_needed`] only, named by `keys`, and `omitted[surface]` is the range of
    /// push numbers of the rows left out (inclusive), whose segments the tree holds unchanged.
    /// Returns false, changing nothing the next full sync needs, when the tree cannot be updated
    /// (it is not kept, or most of the set is new): then sync the whole set.
    pub(crate) fn sync_rows(&mut self, set: &Filaments, keys: &[u64], omitted: &[(u64, u64)]) -> bool {
        self.forget_mixed();
        if keys.len() != set.n_segments() || !self.updatable() {
            return false;
        }
        debug_assert!(keys.windows(2).all(|w| w[0] < w[1]), "segment keys ascend");
        self.partial = self.update(set, keys, Some(omitted));
        if !self.partial {
            // The merge may have recorded strengths it did not apply: rebuild at the next sync.
            self.persist.valid = false;
        }
        self.partial
    }

    /// Merge the tree's keys with the set's: a segment in both takes the set's strength and
    /// core, a segment only in the tree strength 0 (unless its row is `omitted`: the set holds
    /// part of the wake, [`WakeTree::sync_rows`]), a segment only in the set goes to the direct
    /// sum. Returns false (nothing usable) when more than half the set is new.
    fn update(&mut self, set: &Filaments, keys: &[u64], omitted: Option<&[(u64, u64)]>) -> bool {
        let p = &mut self.persist;
        p.direct.clear();
        p.changes.clear();
        let (mut i, mut s) = (0, 0);
        let (mut n_new, mut n_omitted) = (0, 0);
        // The rows left out of the set, per surface: a held key in them starts a run of held
        // keys (that surface and image copy, down to the oldest row left out) passed over at once.
        let left_out = |k: u64| {
            omitted.and_then(|o| {
                let (surface, row) = SegmentKeys::surface_and_row(k);
                o.get(surface).filter(|&&(lo, hi)| (lo..=hi).contains(&row)).map(|&(lo, _)| lo)
            })
        };
        loop {
            let (kt, ks) = (p.keys.get(i), keys.get(s));
            match (kt, ks) {
                (None, None) => break,
                (Some(a), Some(b)) if a == b => {
                    let now = [set.seg_g[s], set.seg_core2[s], set.seg_cut2[s]];
                    // The core constants come from the segment's length: translated nodes may
                    // change their last bits, which changes nothing.
                    let same = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs());
                    let held = p.held[i];
                    if now[0] != held[0] || !same(now[1], held[1]) || !same(now[2], held[2]) {
                        p.changes.push((i as u32, now[0], now[1], now[2]));
                        p.held[i] = now;
                    }
                    (i, s) = (i + 1, s + 1);
                }
                (Some(&a), b) if b.is_none_or(|&b| a < b) => {
                    if let Some(oldest) = left_out(a) {
                        let last = SegmentKeys::last_key_from(a, oldest);
                        let run = p.keys[i..].partition_point(|&k| k <= last);
                        n_omitted += run;
                        i += run;
                        continue;
                    }
                    if p.held[i] != [0.0; 3] {
                        p.changes.push((i as u32, 0.0, 0.0, 0.0));
                        p.held[i] = [0.0; 3];
                    }
                    i += 1;
                }
                _ => {
                    copy_segment(set, s, &mut p.direct);
                    n_new += 1;
                    s += 1;
                }
            }
        }
        if 2 * n_new > keys.len() + n_omitted {
            return false;
        }
        self.tree.set_segments(&p.changes);
        copy_legs(set, &mut p.direct);
        true
    }

    /// Add the velocity induced by `set` at `pts` to `out`: through the treecode (to within
    /// `tol`, m/s) when the aggregation applies to the set, else directly. Returns the pairs
    /// summed directly.
    pub(crate) fn add_velocity(
        &mut self,
        set: &Filaments,
        pts: &Points,
        tol: f64,
        out: &mut [[f64; 3]],
        parallel: Parallel,
        scratch: &mut ScratchPool<NodeBlock>,
    ) -> u64 {
        if pts.is_empty() || (set.n_filaments() == 0 && !self.partial) {
            return 0;
        }
        // A tree built for this use alone pays its build: it breaks even at a larger wake.
        let rebuilt = !(self.ready && self.persist.valid);
        if !self.applies(set)
            || (rebuilt && set.n_segments() < REBUILT_FACTOR.saturating_mul(self.settings.min_segments))
        {
            return match &mut self.mixed {
                // The set is the one of the last sync (every change of it goes through one).
                Some(m) => {
                    m.load_once(set);
                    m.add_velocity(set, pts, out, parallel)
                }
                None => add_direct(set, pts, out, parallel, scratch),
            };
        }
        if !self.ready {
            self.tree.build(set);
            self.ready = true;
            self.persist.valid = false;
        }
        if !self.persist.valid {
            block_order(pts, &mut self.order, &mut self.stack);
            return self.tree.add_velocity_inplace(pts, &self.order, tol, out, parallel);
        }
        let p = &mut self.persist;
        p.shifted.clear();
        for k in 0..pts.len() {
            p.shifted.push([pts.x[k] - p.shift[0], pts.y[k] - p.shift[1], pts.z[k] - p.shift[2]]);
        }
        block_order(&p.shifted, &mut self.order, &mut self.stack);
        let pairs = self.tree.add_velocity_inplace(&p.shifted, &self.order, tol, out, parallel);
        pairs
            + match &mut self.mixed {
                Some(m) => add_velocity_mixed(&p.direct, pts, out, parallel, m),
                None => add_direct(&p.direct, pts, out, parallel, scratch),
            }
    }
}

/// Add the direct induction of `set` at `pts` to `out`.
fn add_direct(
    set: &Filaments,
    pts: &Points,
    out: &mut [[f64; 3]],
    parallel: Parallel,
    scratch: &mut ScratchPool<NodeBlock>,
) -> u64 {
    if set.n_filaments() == 0 {
        return 0;
    }
    if out.iter().all(|u| *u == [0.0; 3]) {
        return induced_velocity_inplace(&[set], pts, out, parallel, scratch);
    }
    let blk = scratch.first();
    let mut pairs = 0;
    for b in 0..pts.len().div_ceil(LANES) {
        pairs += add_block_direct(set, pts, b, out, blk);
    }
    pairs
}

/// Add the direct induction of `set` at block `b` of `pts` to `out`.
fn add_block_direct(set: &Filaments, pts: &Points, b: usize, out: &mut [[f64; 3]], blk: &mut NodeBlock) -> u64 {
    let (px, py, pz) = (load_lanes(&pts.x, b), load_lanes(&pts.y, b), load_lanes(&pts.z, b));
    let mut u = [[0.0; LANES]; 3];
    fill_block(set, &px, &py, &pz, blk);
    velocity_block(set, blk, &mut u);
    for l in 0..LANES.min(pts.len() - b * LANES) {
        for q in 0..3 {
            out[b * LANES + l][q] += u[q][l];
        }
    }
    (LANES * set.n_filaments()) as u64
}

/// Append segment `s` of `set` (its two nodes, strength and core) to `out`.
fn copy_segment(set: &Filaments, s: usize, out: &mut Filaments) {
    let (a, b) = set.segment_nodes(s);
    let a = out.push_node(set.node(a as usize));
    let b = out.push_node(set.node(b as usize));
    out.seg_a.push(a);
    out.seg_b.push(b);
    out.seg_g.push(set.seg_g[s]);
    out.seg_core2.push(set.seg_core2[s]);
    out.seg_cut2.push(set.seg_cut2[s]);
}

/// Append the legs of `set` to `out`.
fn copy_legs(set: &Filaments, out: &mut Filaments) {
    for l in 0..set.n_legs() {
        let a = out.push_node(set.node(set.leg_a[l] as usize));
        out.leg_a.push(a);
        out.leg_d.push(set.leg_d[l]);
        out.leg_g.push(set.leg_g[l]);
        out.leg_core2.push(set.leg_core2[l]);
        out.leg_cut2.push(set.leg_cut2[l]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aic::{SegmentKeys, WakePart, append_wake_rows};
    use crate::biot_savart::CoreModel;
    use crate::images::{ImagePlane, append_images};
    use crate::induce::induced_velocity;
    use crate::wake::Wake;

    /// The far wake of a wing shedding a varying circulation into a uniform stream (16 strips,
    /// a buffer of 40 rows, closure legs, a mirror plane along the stream), marched 80 steps.
    /// At every step the persistent tree's induction is within its tolerance (1e-6 |V∞|) of the
    /// direct sum at points over the wing and the near wake: through the rebuilds, the rows
    /// the full buffer drops and the last edge's change of strength. The tree was kept across
    /// steps and aggregated (the check can fail). A second tree synchronised from the rows it
    /// needs only ([`WakeTree::sync_rows`], whenever it can) gives the same velocities bit for
    /// bit.
    #[test]
    fn a_persistent_tree_follows_a_translating_wake() {
        let (n, rows, dt) = (16, 40, 0.01);
        let v_inf = [10.0, 0.0, 0.0];
        let tol = 1e-6 * 10.0;
        let d = [v_inf[0] * dt, 0.0, 0.0];
        let planes = [ImagePlane::through_origin([0.0, 1.0, 0.0])];
        let core = CoreModel::CutOff { radius: 1e-6 };
        let settings = WakeAggregation { leaf_size: 16, ..WakeAggregation::treecode() };
        let mut tree = WakeTree::new(&settings);
        let mut by_rows = WakeTree::new(&settings);
        let mut n_by_rows = 0;
        let mut wake = Wake::new(n, rows);
        let y = |j: usize| 0.05 + 1.2 * (1.0 - (std::f64::consts::FRAC_PI_2 * j as f64 / n as f64).cos());
        let te: Vec<[f64; 3]> = (0..=n).map(|j| [0.0, y(j), 0.02 * y(j) * y(j)]).collect();
        let mut pts = Points::default();
        for i in 0..6 {
            for j in 0..=n {
                let p = te[j];
                pts.push([p[0] - 0.25 + 0.08 * i as f64, p[1] + 0.01, p[2] + 0.004 * i as f64]);
            }
        }
        let mut scratch = ScratchPool::default();
        let (mut kept, mut aggregated) = (0, false);
        for step in 0..80 {
            wake.translate(d);
            tree.translate(d);
            by_rows.translate(d);
            let row: Vec<[f64; 3]> = te.iter().map(|p| [p[0] + d[0], p[1], p[2]]).collect();
            let t = step as f64 * dt;
            let gamma: Vec<f64> = (0..n)
                .map(|j| {
                    let s = (j as f64 + 0.5) / n as f64;
                    (1.0 - s * s).sqrt() * (1.0 + 0.3 * (9.0 * t).sin())
                })
                .collect();
            wake.push_front(&row, &gamma);
            // The far wake with its images and names: whole, or only the node rows `rows`.
            let far = |rows: Option<FarRows>| {
                let (mut fil, mut keys) = (Filaments::default(), SegmentKeys::default());
                let (closure, part) = (Some([1.0, 0.0, 0.0]), WakePart::Far);
                append_wake_rows(&mut fil, &te, &wake, closure, &core, &core, part, rows, Some(&mut keys));
                append_images(&mut fil, &planes);
                keys.append_images(planes.len());
                (fil, keys)
            };
            let (fil, keys) = far(None);
            tree.sync(&fil, Some(&keys.keys));
            if tree.persist.age > 0 {
                kept += 1;
            }
            let mut u = vec![[0.0; 3]; pts.len()];
            tree.add_velocity(&fil, &pts, tol, &mut u, Parallel::Off, &mut scratch);
            let synced = by_rows.rows_needed(wake.n_rows()).is_some_and(|r| {
                let (part, keys) = far(Some(r));
                let np = wake.n_pushed();
                let omitted = [(np - (r.1 - 1) as u64, np - (r.0 + 1) as u64)];
                assert!(part.n_segments() < fil.n_segments(), "step {step}: rows left out");
                by_rows.sync_rows(&part, &keys.keys, &omitted)
            });
            if synced {
                n_by_rows += 1;
            } else {
                by_rows.sync(&fil, Some(&keys.keys));
            }
            let mut v = vec![[0.0; 3]; pts.len()];
            by_rows.add_velocity(&fil, &pts, tol, &mut v, Parallel::Off, &mut scratch);
            assert_eq!(u, v, "step {step}: the tree synchronised from rows differs");
            aggregated |= tree.tree.stats().n_expansions > 0;
            let points: Vec<[f64; 3]> = (0..pts.len()).map(|k| [pts.x[k], pts.y[k], pts.z[k]]).collect();
            let direct = induced_velocity(&[&fil], &points);
            let err = u
                .iter()
                .zip(&direct)
                .map(|(a, b)| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt())
                .fold(0.0, f64::max);
            assert!(err <= tol, "step {step}: error {err:e} > {tol:e}");
        }
        assert!(kept >= 60, "the tree was kept at {kept} of 80 steps");
        assert!(n_by_rows >= 50, "synchronised from rows at {n_by_rows} of 80 steps");
        assert!(aggregated, "nothing aggregated");
    }
}
