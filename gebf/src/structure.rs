//! [`formulation::Structure`] for the GEBF model: what the analyses need from it, with the
//! section interpolation of the aerodynamic seam.

use formulation::{BeamGeometry, Energies, LoadError, Momentum, SectionLoad, Structure};
use genalpha::{DenseLu, GenAlpha, IntegratorParams, State};
use nalgebra::{Matrix3, Vector3};

use crate::crv::rotation_matrix;
use crate::{Model, NodalLoad};

impl Model {
    /// Element of body `body` holding arclength `s`: its three node indices and the quadratic
    /// Lagrange weights of `s` (the first or last element beyond the body's ends).
    pub fn section_element(&self, body: usize, s: f64) -> Option<([usize; 3], [f64; 3])> {
        let b = self.bodies.get(body)?;
        let n = b.n_nodes();
        let arc = |k: usize| b.node_ref(k).x;
        let n_el = (n - 1) / 2;
        for e in 0..n_el {
            let (s0, s1, s2) = (arc(2 * e), arc(2 * e + 1), arc(2 * e + 2));
            if s <= s2 + 1e-12 || e + 1 == n_el {
                let w = [
                    (s - s1) * (s - s2) / ((s0 - s1) * (s0 - s2)),
                    (s - s0) * (s - s2) / ((s1 - s0) * (s1 - s2)),
                    (s - s0) * (s - s1) / ((s2 - s0) * (s2 - s1)),
                ];
                return Some(([2 * e, 2 * e + 1, 2 * e + 2], w));
            }
        }
        None
    }
}

/// What a section pose interpolates on one element: the three node positions, the middle
/// node's frame and the end nodes' rotation vectors relative to it (and the last node's frame,
/// which the next element of the body starts from).
struct ElementPose {
    positions: [Vector3<f64>; 3],
    middle: Matrix3<f64>,
    ends: [Vector3<f64>; 2],
    last: Matrix3<f64>,
}

/// A node's position and frame, [`Model::node_position`] and [`Model::node_frame`] bit for bit,
/// with the body's frame rotation matrix computed once for its nodes (NaN for a node or body
/// the model does not have).
struct NodePoses<'a> {
    q: &'a [f64],
    body: usize,
    /// The body, its frame position and orientation, and that orientation's matrix.
    frame: Option<(&'a crate::body::Body, Vector3<f64>, crate::quaternion::Quaternion, Matrix3<f64>)>,
}

impl<'a> NodePoses<'a> {
    fn new(model: &'a Model, q: &'a [f64], body: usize) -> Self {
        let frame = model.bodies.get(body).map(|b| {
            let (r, chi) = b.frame_state(q);
            (b, r, chi, chi.to_rotation_matrix())
        });
        Self { q, body, frame }
    }

    fn position(&self, k: usize) -> Vector3<f64> {
        match &self.frame {
            Some((b, r, chi, _)) if k < b.n_nodes() => r + chi.rotate(&b.node_state(self.q, k).0),
            _ => Vector3::from_element(f64::NAN),
        }
    }

    fn frame(&self, k: usize) -> Matrix3<f64> {
        match &self.frame {
            Some((b, _, _, c)) if k < b.n_nodes() => c * rotation_matrix(&b.node_state(self.q, k).1),
            _ => Matrix3::from_element(f64::NAN),
        }
    }
}

impl ElementPose {
    /// The element of `nodes` on the body of `nodes_at`; `start`: its first node's position and
    /// frame when the previous element (ending there) has them.
    fn new(nodes_at: &NodePoses<'_>, nodes: [usize; 3], start: Option<(Vector3<f64>, Matrix3<f64>)>) -> Self {
        let log = |r: &Matrix3<f64>| crate::crv::from_rotation_matrix(r);
        let (p0, f0) = start.unwrap_or_else(|| (nodes_at.position(nodes[0]), nodes_at.frame(nodes[0])));
        let middle = nodes_at.frame(nodes[1]);
        let last = nodes_at.frame(nodes[2]);
        Self {
            positions: [p0, nodes_at.position(nodes[1]), nodes_at.position(nodes[2])],
            middle,
            ends: [log(&(middle.transpose() * f0)), log(&(middle.transpose() * last))],
            last,
        }
    }

    /// The pose at the quadratic shape-function weights `w`.
    fn at(&self, w: [f64; 3]) -> (Vector3<f64>, Matrix3<f64>) {
        let [p0, p1, p2] = &self.positions;
        let p = p0 * w[0] + p1 * w[1] + p2 * w[2];
        let phi = self.ends[0] * w[0] + self.ends[1] * w[2];
        (p, self.middle * nalgebra::Rotation3::new(phi).into_inner())
    }
}

impl Structure for Model {
    /// genalpha's default solver, which switches to the bordered node-block LU from GEBF's
    /// declared block-banded structure.
    type Solver = DenseLu;
    fn integrator(&self, params: IntegratorParams) -> Result<GenAlpha<DenseLu>, genalpha::Error> {
        GenAlpha::new(params, self)
    }
    fn initial_state(&self) -> State {
        Model::initial_state(self)
    }
    fn tip(&self, q: &[f64]) -> [f64; 3] {
        self.tip_position(q).into()
    }
    fn fold(&self, q: &[f64], joint: usize) -> f64 {
        self.fold_angle(q, joint).unwrap_or(f64::NAN)
    }
    fn hinge_rate(&self, q: &[f64], v: &[f64], joint: usize) -> f64 {
        Model::hinge_rate(self, q, v, joint).unwrap_or(f64::NAN)
    }
    fn energies(&self, q: &[f64], v: &[f64]) -> Energies {
        Model::energies(self, q, v)
    }
    fn momentum(&self, q: &[f64], v: &[f64]) -> Momentum {
        Model::momentum(self, q, v)
    }
    fn start_march(&mut self, t: f64, q: &[f64], v: &[f64]) {
        self.hold_momentum(t, q, v);
    }
    fn dissipation_power(&self, q: &[f64], v: &[f64]) -> f64 {
        Model::dissipation_power(self, q, v)
    }
    fn has_force_elements(&self) -> bool {
        self.n_force_elements() > 0
    }
    fn external_power(&self, t: f64, q: &[f64], v: &[f64]) -> f64 {
        self.thrust_power(t, q, v)
    }
    fn has_external_power(&self) -> bool {
        self.has_thrust()
    }
    fn constraint_residual(&self, q: &[f64]) -> f64 {
        Model::constraint_residual(self, q)
    }
    fn n_bodies(&self) -> usize {
        Model::n_bodies(self)
    }
    fn body_length(&self, body: usize) -> Option<f64> {
        self.bodies.get(body).map(|b| b.length)
    }
    /// Every node of the three-node elements, middle nodes included.
    fn body_geometry(&self, q: &[f64], body: usize, out: &mut BeamGeometry) {
        out.clear();
        if body >= self.bodies.len() {
            return;
        }
        for k in 0..self.n_nodes(body) {
            if let (Ok(s), Ok(p), Ok(r)) =
                (self.node_arc_length(body, k), self.node_position(q, body, k), self.node_frame(q, body, k))
            {
                out.push(s, p, r);
            }
        }
    }
    /// Quadratic interpolation of the element's nodal positions, and of the nodal rotations
    /// relative to the middle node (objective). The relative rotations' vectors come through the
    /// quaternion ([`crate::crv::from_rotation_matrix`], Shepperd's method), accurate at every
    /// angle: an `acos` of the trace returns NaN when rounding pushes it past 3 for the tiny
    /// relative rotations of a stiff wing.
    fn section_pose(&self, q: &[f64], body: usize, s: f64) -> (Vector3<f64>, Matrix3<f64>) {
        match self.section_element(body, s) {
            Some((nodes, w)) => ElementPose::new(&NodePoses::new(self, q, body), nodes, None).at(w),
            None => (Vector3::from_element(f64::NAN), Matrix3::identity()),
        }
    }
    /// The element's node positions, middle frame and end rotation vectors are computed once
    /// for the consecutive stations on it, its first node's from the element before it on the
    /// body, and the body's frame rotation once per run of stations on the body (bit for bit
    /// [`section_pose`](Self::section_pose)).
    fn section_poses(&self, q: &[f64], at: &[(usize, f64)], out: &mut Vec<(Vector3<f64>, Matrix3<f64>)>) {
        out.clear();
        let mut nodes_at: Option<NodePoses<'_>> = None;
        let mut current: Option<(usize, [usize; 3], ElementPose)> = None;
        for &(body, s) in at {
            let Some((nodes, w)) = self.section_element(body, s) else {
                out.push((Vector3::from_element(f64::NAN), Matrix3::identity()));
                continue;
            };
            let poses = match &mut nodes_at {
                Some(n) if n.body == body => n,
                slot => slot.insert(NodePoses::new(self, q, body)),
            };
            let pose = match &current {
                Some((b, n, pose)) if *b == body && *n == nodes => pose,
                _ => {
                    // The previous element on the body ends where this one starts.
                    let start = match &current {
                        Some((b, n, pose)) if *b == body && n[2] == nodes[0] => Some((pose.positions[2], pose.last)),
                        _ => None,
                    };
                    &current.insert((body, nodes, ElementPose::new(&*poses, nodes, start))).2
                }
            };
            out.push(pose.at(w));
        }
    }
    /// Consistent nodal loads: the quadratic weights distribute each station's force and moment.
    fn apply_section_loads(&mut self, loads: &[SectionLoad]) -> Result<(), LoadError> {
        self.clear_nodal_loads();
        for l in loads {
            let Some((nodes, w)) = self.section_element(l.body, l.s) else { continue };
            for (k, wk) in nodes.iter().zip(w) {
                let old = self.loads[l.body][*k];
                let new = NodalLoad { force: old.force + wk * l.force, moment: old.moment + wk * l.moment };
                self.set_nodal_load(l.body, *k, new).map_err(|e| LoadError::Model(e.to_string()))?;
            }
        }
        Ok(())
    }
    /// Rotation vectors back past π, and the joints' position-level projection: the
    /// velocity-level hinge rows keep each Newton increment on the joint only to first order.
    fn normalise(&self, q: &mut [f64]) {
        self.rescale_rotations(q, None);
        self.project_joints(q);
    }
}
