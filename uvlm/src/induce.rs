//! Induced-velocity evaluation at many points: block loop, optional rayon threading.

use crate::biot_savart::{Filaments, LANES, NodeBlock, fill_block, load_lanes, velocity_block};
use crate::params::{PARALLEL_MIN_PAIRS, Parallel};
use rayon::prelude::*;
use std::cell::RefCell;

thread_local! {
    /// Per-thread block scratch for the parallel path (allocated once per thread, then reused).
    static BLOCK: RefCell<NodeBlock> = RefCell::new(NodeBlock::default());
}

/// Evaluation points in structure-of-arrays layout.
#[derive(Debug, Clone, Default)]
pub struct Points {
    /// x coordinates, m.
    pub x: Vec<f64>,
    /// y coordinates, m.
    pub y: Vec<f64>,
    /// z coordinates, m.
    pub z: Vec<f64>,
}

impl Points {
    /// Remove all points, keeping capacity.
    pub fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
    }
    /// Append a point.
    pub fn push(&mut self, p: [f64; 3]) {
        self.x.push(p[0]);
        self.y.push(p[1]);
        self.z.push(p[2]);
    }
    /// Number of points.
    pub fn len(&self) -> usize {
        self.x.len()
    }
    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
}

/// Whether an evaluation of `pairs` point–filament pairs should run on rayon.
pub(crate) fn use_threads(parallel: Parallel, pairs: usize) -> bool {
    match parallel {
        Parallel::Off => false,
        Parallel::Auto => {
            let t = rayon::current_num_threads();
            t > 1 && pairs >= PARALLEL_MIN_PAIRS * t
        }
    }
}

fn eval_block(sets: &[&Filaments], pts: &Points, b: usize, blk: &mut NodeBlock, out: &mut [[f64; 3]]) {
    let (px, py, pz) = (load_lanes(&pts.x, b), load_lanes(&pts.y, b), load_lanes(&pts.z, b));
    let mut u = [[0.0; LANES]; 3];
    for set in sets {
        if set.n_filaments() == 0 {
            continue;
        }
        fill_block(set, &px, &py, &pz, blk);
        velocity_block(set, blk, &mut u);
    }
    for (l, o) in out.iter_mut().enumerate() {
        *o = [u[0][l], u[1][l], u[2][l]];
    }
}

/// Velocity induced at every point by the union of `sets`, written to `out` (one entry per point).
/// Returns the number of point–filament pairs evaluated (padded to whole blocks).
///
/// # Panics
/// If `out.len() != pts.len()`.
pub(crate) fn induced_velocity_inplace(
    sets: &[&Filaments],
    pts: &Points,
    out: &mut [[f64; 3]],
    parallel: Parallel,
    blk: &mut NodeBlock,
) -> u64 {
    assert_eq!(out.len(), pts.len(), "induced_velocity_inplace: output length");
    if pts.is_empty() {
        return 0;
    }
    let n_fil: usize = sets.iter().map(|s| s.n_filaments()).sum();
    let n_blocks = pts.len().div_ceil(LANES);
    let pairs = n_blocks * LANES * n_fil;
    if use_threads(parallel, pairs) {
        out.par_chunks_mut(LANES).enumerate().for_each(|(b, chunk)| {
            BLOCK.with(|cell| eval_block(sets, pts, b, &mut cell.borrow_mut(), chunk));
        });
    } else {
        for (b, chunk) in out.chunks_mut(LANES).enumerate() {
            eval_block(sets, pts, b, blk, chunk);
        }
    }
    pairs as u64
}

/// Velocity induced by `sets` at `points` (allocating convenience; sequential).
pub fn induced_velocity(sets: &[&Filaments], points: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut pts = Points::default();
    for p in points {
        pts.push(*p);
    }
    let mut out = vec![[0.0; 3]; points.len()];
    induced_velocity_inplace(sets, &pts, &mut out, Parallel::Off, &mut NodeBlock::default());
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::biot_savart::CoreModel;
    use approx::assert_relative_eq;

    #[test]
    fn threaded_equals_sequential() {
        let mut fil = Filaments::default();
        let core = CoreModel::CutOff { radius: 1e-9 };
        let n = 120;
        for i in 0..=n {
            let t = i as f64 / n as f64;
            fil.push_node([t, (7.0 * t).sin(), 0.1 * t]);
        }
        for i in 0..n as u32 {
            fil.push_segment(i, i + 1, 1.0 + 0.01 * i as f64, &core);
        }
        let mut pts = Points::default();
        for k in 0..2000 {
            let t = k as f64 * 0.001;
            pts.push([t, 0.5 - t, 0.3]);
        }
        let mut a = vec![[0.0; 3]; pts.len()];
        let mut b = vec![[0.0; 3]; pts.len()];
        let mut blk = NodeBlock::default();
        induced_velocity_inplace(&[&fil], &pts, &mut a, Parallel::Off, &mut blk);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        pool.install(|| {
            // 2000 points × 120 segments < threshold × 2: force through the parallel branch directly.
            b.par_chunks_mut(LANES).enumerate().for_each(|(k, chunk)| {
                BLOCK.with(|cell| eval_block(&[&fil], &pts, k, &mut cell.borrow_mut(), chunk));
            });
        });
        for (u, v) in a.iter().zip(&b) {
            for q in 0..3 {
                assert_relative_eq!(u[q], v[q], max_relative = 1e-15, epsilon = 1e-300);
            }
        }
        let s = fil.velocity_at([0.3, 0.2, 0.3]);
        assert_relative_eq!(a[300][2], s[2], max_relative = 1e-12);
    }
}
