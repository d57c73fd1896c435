//! A body's nodes in the current configuration, for outputs.

use nalgebra::{Matrix3, Vector3};

/// One body's nodes in the current configuration.
///
/// ```
/// use nalgebra::{Matrix3, Vector3};
/// let mut g = formulation::BeamGeometry::default();
/// g.push(0.0, Vector3::zeros(), Matrix3::identity());
/// g.push(0.5, Vector3::new(0.5, 0.0, 0.0), Matrix3::identity());
/// assert_eq!(g.arc, [0.0, 0.5]);
/// g.clear();
/// assert!(g.positions.is_empty());
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BeamGeometry {
    /// Arclength of each node in the reference configuration, m.
    pub arc: Vec<f64>,
    /// Node positions, global, m.
    pub positions: Vec<Vector3<f64>>,
    /// Section frames at the nodes: columns x (beam axis), y, z, global.
    pub frames: Vec<Matrix3<f64>>,
}

impl BeamGeometry {
    /// Forget the nodes, keep the storage.
    pub fn clear(&mut self) {
        self.arc.clear();
        self.positions.clear();
        self.frames.clear();
    }

    /// Append a node.
    pub fn push(&mut self, arc: f64, position: Vector3<f64>, frame: Matrix3<f64>) {
        self.arc.push(arc);
        self.positions.push(position);
        self.frames.push(frame);
    }
}
