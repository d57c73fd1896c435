//! The wake: rows of vortex rings shed from the trailing edge, stored as a ring buffer.
//!
//! Wake ring row `r` (0 = newest) lies between node row `r` and node row `r + 1`, where node row
//! 0 is the lattice's trailing-edge ring row (shared, not stored here) and the stored
//! ("detached") node row `r` is node row `r + 1`. Shedding pushes a row at the front; when the
//! buffer is full the oldest row is overwritten (truncation). Nothing moves in memory.

/// Ring buffer of wake rows.
#[derive(Debug, Clone)]
pub struct Wake {
    n: usize,
    capacity: usize,
    head: usize,
    len: usize,
    nodes: Vec<[f64; 3]>,
    gamma: Vec<f64>,
    /// Rows pushed since construction (never reset): row `r` is push number `n_pushed − 1 − r`.
    n_pushed: u64,
}

impl Wake {
    /// An empty wake of up to `capacity` ring rows behind `n_spanwise` trailing-edge panels.
    pub fn new(n_spanwise: usize, capacity: usize) -> Self {
        Self {
            n: n_spanwise,
            capacity,
            head: 0,
            len: 0,
            nodes: vec![[0.0; 3]; capacity * (n_spanwise + 1)],
            gamma: vec![0.0; capacity * n_spanwise],
            n_pushed: 0,
        }
    }

    /// Number of ring rows currently in the wake.
    pub fn n_rows(&self) -> usize {
        self.len
    }
    /// Maximum number of ring rows.
    pub fn capacity(&self) -> usize {
        self.capacity
    }
    /// Number of rings per row.
    pub fn n_spanwise(&self) -> usize {
        self.n
    }

    /// Rows pushed since construction, including those dropped and cleared: row `r` is push
    /// number `n_pushed() − 1 − r`, a name that stays with the row as newer rows arrive.
    pub fn n_pushed(&self) -> u64 {
        self.n_pushed
    }

    #[inline]
    fn phys(&self, r: usize) -> usize {
        debug_assert!(r < self.len);
        // `head < capacity` and `r < len ≤ capacity`: one conditional subtraction, not the
        // integer division of `%` (tens of cycles, on every node the Biot–Savart sets read).
        let p = self.head + r;
        if p >= self.capacity { p - self.capacity } else { p }
    }

    /// Downstream node `j` of ring row `r` (the detached node row `r`), m.
    #[inline]
    pub fn node(&self, r: usize, j: usize) -> [f64; 3] {
        self.nodes[self.phys(r) * (self.n + 1) + j]
    }

    /// Circulation of wake ring `(r, j)`, m²/s.
    #[inline]
    pub fn gamma(&self, r: usize, j: usize) -> f64 {
        self.gamma[self.phys(r) * self.n + j]
    }

    /// Set the circulations of ring row `r`.
    pub fn set_gamma_row(&mut self, r: usize, g: &[f64]) {
        let p = self.phys(r) * self.n;
        self.gamma[p..p + self.n].copy_from_slice(g);
    }

    /// Shed a row at the front: its downstream nodes and circulations. Drops the oldest row when full.
    ///
    /// # Panics
    /// If the slices do not have `n_spanwise + 1` and `n_spanwise` entries.
    pub fn push_front(&mut self, nodes: &[[f64; 3]], gamma: &[f64]) {
        assert!(nodes.len() == self.n + 1 && gamma.len() == self.n, "wake row length mismatch");
        self.head = (self.head + self.capacity - 1) % self.capacity;
        self.len = (self.len + 1).min(self.capacity);
        self.n_pushed += 1;
        let p = self.head;
        self.nodes[p * (self.n + 1)..(p + 1) * (self.n + 1)].copy_from_slice(nodes);
        self.gamma[p * self.n..(p + 1) * self.n].copy_from_slice(gamma);
    }

    /// Move every stored node by `d`, m.
    pub fn translate(&mut self, d: [f64; 3]) {
        for r in 0..self.len {
            let p = self.phys(r) * (self.n + 1);
            for x in &mut self.nodes[p..p + self.n + 1] {
                x[0] += d[0];
                x[1] += d[1];
                x[2] += d[2];
            }
        }
    }

    /// Move node `(r, j)` by `d`, m.
    #[inline]
    pub fn displace(&mut self, r: usize, j: usize, d: [f64; 3]) {
        let k = self.phys(r) * (self.n + 1) + j;
        for q in 0..3 {
            self.nodes[k][q] += d[q];
        }
    }

    /// Remove every row.
    pub fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_buffer_truncates_oldest() {
        let mut w = Wake::new(2, 3);
        for k in 0..5 {
            let x = k as f64;
            w.translate([1.0, 0.0, 0.0]);
            w.push_front(&[[x, 0.0, 0.0], [x, 1.0, 0.0], [x, 2.0, 0.0]], &[x, -x]);
        }
        assert_eq!(w.n_rows(), 3);
        // Newest row: k = 4, never translated; oldest kept: k = 2, translated twice.
        assert_eq!(w.node(0, 1), [4.0, 1.0, 0.0]);
        assert_eq!(w.gamma(0, 1), -4.0);
        assert_eq!(w.node(2, 2), [4.0, 2.0, 0.0]);
        assert_eq!(w.gamma(2, 0), 2.0);
    }
}
