//! Wing loads from a free body: the root wrench at a clamp (or at the case's `root_joint`, a
//! wing's root on a free aircraft) and the hinge moment of a flared hinge, from the aerodynamic
//! station loads, gravity and (in time histories) the inertia of the distributed mass and the
//! point masses (docs/statics.md §4).
//!
//! Both formulations are measured by the same rule, written once against [`Structure`]: the
//! free body is the set of bodies outboard of the cut, and its loads are integrated along the
//! bodies' section poses (3-point Gauss–Legendre on each of the formulation's elements, so the
//! rule is exact for the polynomial interpolation inside an element). Accelerations come from the
//! second central difference of the pose along the model's retraction
//! `q ∘ exp(±ε v + ½ ε² v̇)`, which matches the trajectory to second order.
//!
//! Conventions (the clamp's section frame `x_c` span, `y_c` towards the leading edge, `z_c`):
//! * root bending moment `−M·y_c`: positive when lift (+`z_c`) bends the wing up;
//! * root torque `M·x_c`: nose-up positive;
//! * hinge moment: the moment of the loads on the outboard bodies about the hinge axis, positive
//!   in the fold-up sense (about `−a`, `a = sin β x + cos β y` of the parent's end section), i.e.
//!   the moment the hinge must carry: zero for a free hinge at rest, the spring's moment for a
//!   sprung one, the lock's for a locked one.

use nalgebra::{Matrix3, Vector3};

use formulation::{SectionMotion, Structure};

use crate::problem::{Formulation, Joint, Problem};
use formulation::SectionLoad;

/// The cut of a free body: its bodies and the point moments are taken about.
#[derive(Debug, Clone, PartialEq)]
struct Cut {
    /// Bodies outboard of the cut.
    bodies: Vec<usize>,
}

/// Mass data of one body for the free body.
#[derive(Debug, Clone, PartialEq)]
struct BodyMass {
    length: f64,
    n_elements: usize,
    mass: f64,
    cg: [f64; 2],
    rho_i: [f64; 3],
    points: Vec<crate::problem::PointMass>,
}

/// Root and hinge loads of a case's wing at one state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct WingLoads {
    /// Root force in the clamp's section frame `[axial, chordwise, normal]`, N (the load the
    /// wing puts on the clamp).
    pub root_force: [f64; 3],
    /// Root moment in the clamp's section frame, about the clamp's axis point, N·m.
    pub root_moment: [f64; 3],
    /// Root bending moment, N·m (positive when lift bends the wing up).
    pub root_bending_moment: f64,
    /// Root torque, N·m (nose-up positive).
    pub root_torque: f64,
    /// Hinge moment about the hinge axis, N·m (fold-up positive; NaN without a flared hinge).
    pub hinge_moment: f64,
}

/// What a case's free bodies need: the clamp, the fold hinge, the bodies' mass and gravity.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadModel {
    bodies: Vec<BodyMass>,
    clamp: Option<(usize, Cut)>,
    hinge: Option<(usize, f64, Cut)>,
    gravity: Vector3<f64>,
}

/// Gauss–Legendre abscissae and weights on [0, 1], 3 points.
const GAUSS3: [(f64, f64); 3] =
    [(0.112_701_665_379_258_3, 5.0 / 18.0), (0.5, 8.0 / 18.0), (0.887_298_334_620_741_7, 5.0 / 18.0)];

impl LoadModel {
    /// The free bodies of `case` as formulation `f` discretises it: the root body
    /// ([`Problem::root_body_index`]: the `root_joint`'s child, or the first clamp's body) and
    /// everything joined outboard of it, and the outboard side of the fold hinge
    /// ([`Problem::fold_joint_index`]). `None` when the case has neither.
    pub fn new(case: &Problem, f: Formulation) -> Option<Self> {
        let n_el = case.block(f).elements_per_body;
        let bodies: Vec<BodyMass> = case
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| BodyMass {
                length: b.length,
                n_elements: n_el.for_body(i).max(1),
                mass: b.section.mass,
                cg: b.section.cg_offset,
                rho_i: [b.section.rho_ixx, b.section.rho_iyy, b.section.rho_izz],
                points: b.point_masses.clone(),
            })
            .collect();
        // Children of each body through flared hinges (locked or not).
        let children = |b: usize| -> Vec<usize> {
            case.joints
                .iter()
                .filter_map(|j| match j {
                    Joint::FlaredHinge { parent, child, .. } if case.body_index(parent) == Some(b) => {
                        case.body_index(child)
                    }
                    _ => None,
                })
                .collect()
        };
        let subtree = |root: usize| -> Cut {
            let mut out = vec![root];
            let mut k = 0;
            while k < out.len() && out.len() <= case.bodies.len() {
                for c in children(out[k]) {
                    if !out.contains(&c) {
                        out.push(c);
                    }
                }
                k += 1;
            }
            Cut { bodies: out }
        };
        let clamp = case.root_body_index().map(|b| (b, subtree(b)));
        let hinge = case.fold_joint_index().and_then(|i| match &case.joints[i] {
            Joint::FlaredHinge { parent, child, flare_deg, .. } => {
                let (p, c) = (case.body_index(parent)?, case.body_index(child)?);
                Some((p, flare_deg.to_radians(), subtree(c)))
            }
            _ => None,
        });
        if clamp.is_none() && hinge.is_none() {
            return None;
        }
        let gravity = case.gravity.map(Vector3::from).unwrap_or_else(Vector3::zeros);
        Some(Self { bodies, clamp, hinge, gravity })
    }

    /// Whether the case has a clamp (root loads).
    pub fn has_root(&self) -> bool {
        self.clamp.is_some()
    }

    /// The loads at state `(q, v, v̇)` (`None` for the velocities: at rest) with the
    /// aerodynamic station loads `aero`.
    pub fn evaluate<S: Structure + ?Sized>(
        &self,
        model: &S,
        q: &[f64],
        motion: Option<(&[f64], &[f64])>,
        aero: &[SectionLoad],
        scratch: &mut LoadScratch,
    ) -> WingLoads {
        let mut out = WingLoads { hinge_moment: f64::NAN, ..WingLoads::default() };
        scratch.prepare(model, q, motion);
        if let Some((body, cut)) = &self.clamp {
            let (p, r) = model.section_pose(q, *body, 0.0);
            let (f, m) = self.wrench(model, cut, p, aero, scratch);
            let (fl, ml) = (r.transpose() * f, r.transpose() * m);
            out.root_force = fl.into();
            out.root_moment = ml.into();
            out.root_bending_moment = -ml.y;
            out.root_torque = ml.x;
        } else {
            out.root_force = [f64::NAN; 3];
            out.root_moment = [f64::NAN; 3];
            out.root_bending_moment = f64::NAN;
            out.root_torque = f64::NAN;
        }
        if let Some((parent, beta, cut)) = &self.hinge {
            let (p, r) = model.section_pose(q, *parent, self.bodies[*parent].length);
            let a = r * Vector3::new(beta.sin(), beta.cos(), 0.0);
            let (_, m) = self.wrench(model, cut, p, aero, scratch);
            out.hinge_moment = -m.dot(&a);
        }
        out
    }

    /// Resultant force and moment about `about` of every load on the bodies of `cut`.
    fn wrench<S: Structure + ?Sized>(
        &self,
        model: &S,
        cut: &Cut,
        about: Vector3<f64>,
        aero: &[SectionLoad],
        scratch: &mut LoadScratch,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let (mut f, mut m) = (Vector3::zeros(), Vector3::zeros());
        scratch.ensure_aero_points(model, aero);
        for (l, p) in aero.iter().zip(&scratch.aero_points).filter(|(l, _)| cut.bodies.contains(&l.body)) {
            f += l.force;
            m += (p - about).cross(&l.force) + l.moment;
        }
        for &b in &cut.bodies {
            let Some(bm) = self.bodies.get(b) else { continue };
            let h = bm.length / bm.n_elements as f64;
            scratch.ensure_gauss(model, b, bm);
            for (k, (_, w)) in scratch.gauss[b].iter().zip(GAUSS3.iter().cycle()) {
                let cg = k.offset_point(Vector3::new(0.0, bm.cg[0], bm.cg[1]));
                let df = bm.mass * (self.gravity - cg.1) * (w * h);
                f += df;
                m += (cg.0 - about).cross(&df);
                m += k.rotary_moment(Vector3::from(bm.rho_i)) * (w * h);
            }
            for pm in &bm.points {
                let k = scratch.kinematics(model, b, pm.at);
                let (x, acc) = k.offset_point(Vector3::from(pm.offset));
                let df = pm.mass * (self.gravity - acc);
                f += df;
                m += (x - about).cross(&df) + k.rotary_moment(Vector3::from(pm.inertia));
            }
        }
        (f, m)
    }
}

/// Pose, velocity and acceleration of a section.
#[derive(Debug, Clone)]
struct Kinematics {
    p: Vector3<f64>,
    r: Matrix3<f64>,
    acc: Vector3<f64>,
    /// Second difference of the frame, R̈ (zero at rest).
    r_dd: Matrix3<f64>,
    omega: Vector3<f64>,
    alpha: Vector3<f64>,
}

impl Kinematics {
    /// From a model's exact motion: `R̈ = (ω̃² + α̃) R`.
    fn from_motion(m: &SectionMotion) -> Self {
        let w = m.omega.cross_matrix();
        Kinematics {
            p: m.p,
            r: m.r,
            acc: m.acc,
            r_dd: (w * w + m.alpha.cross_matrix()) * m.r,
            omega: m.omega,
            alpha: m.alpha,
        }
    }

    /// Position and acceleration of the point at `offset` (section frame) from the axis point.
    fn offset_point(&self, offset: Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        (self.p + self.r * offset, self.acc + self.r_dd * offset)
    }

    /// Inertial moment −(J α + ω × J ω) of principal inertias `j` along the section axes.
    fn rotary_moment(&self, j: Vector3<f64>) -> Vector3<f64> {
        if j == Vector3::zeros() {
            return Vector3::zeros();
        }
        let jg = self.r * Matrix3::from_diagonal(&j) * self.r.transpose();
        -(jg * self.alpha + self.omega.cross(&(jg * self.omega)))
    }
}

/// Reused buffers of [`LoadModel::evaluate`]: the states `q`, `q(±ε)` and `q(±2ε)`, and what
/// one evaluation computes once for both cuts (the hinge's free body lies inside the root's):
/// the aerodynamic stations' points and each body's kinematics at its Gauss points.
#[derive(Debug, Clone, Default)]
pub struct LoadScratch {
    q: [Vec<f64>; 5],
    dq: Vec<f64>,
    eps: f64,
    moving: bool,
    at: Vec<(usize, f64)>,
    poses: [Vec<(Vector3<f64>, Matrix3<f64>)>; 5],
    aero_points: Vec<Vector3<f64>>,
    aero_ready: bool,
    /// Per body, the kinematics at its Gauss points in (element, point) order; empty until used.
    gauss: Vec<Vec<Kinematics>>,
    /// The velocities and accelerations of a moving state.
    v: Vec<f64>,
    a: Vec<f64>,
    /// The model gives the sections' motions exactly ([`Structure::section_motions`]), so the
    /// states `q(±ε)`, `q(±2ε)` are made only if a station needs them (`probes`: made).
    exact: bool,
    probes: bool,
    motions: Vec<SectionMotion>,
}

/// Multiples of ε of the states `q[1..]` of [`LoadScratch`].
const STEPS: [f64; 4] = [1.0, -1.0, 2.0, -2.0];

impl LoadScratch {
    fn prepare<S: Structure + ?Sized>(&mut self, model: &S, q: &[f64], motion: Option<(&[f64], &[f64])>) {
        self.q[0].clear();
        self.q[0].extend_from_slice(q);
        self.moving = false;
        self.aero_ready = false;
        self.gauss.iter_mut().for_each(Vec::clear);
        let Some((v, a)) = motion else { return };
        let vmax = v.iter().chain(a).fold(0.0_f64, |m, x| m.max(x.abs()));
        if vmax == 0.0 {
            return;
        }
        self.moving = true;
        self.v.clear();
        self.v.extend_from_slice(v);
        self.a.clear();
        self.a.extend_from_slice(a);
        self.probes = false;
        self.exact = model.section_motions(q, v, a, &[], &mut self.motions);
        if !self.exact {
            self.make_probes(model);
        }
    }

    /// The states `q(±ε)`, `q(±2ε)` along the trajectory of the moving state.
    fn make_probes<S: Structure + ?Sized>(&mut self, model: &S) {
        self.probes = true;
        let (q, v, a) = (&self.q[0], &self.v, &self.a);
        let vmax = v.iter().chain(a).fold(0.0_f64, |m, x| m.max(x.abs()));
        // Fourth-order differences along the curve q ∘ exp(h v + ½ h² v̇), h = kε: the
        // states move by about d = ε² max|v̇| ≈ 6e-6, so that the truncation, O(d²), and the
        // round-off of the positions, about 5e-16 / d, are both near 1e-10 of the
        // accelerations. Second differences at d = 1e-8 had round-off near 1e-8, which the
        // root loads' inertial terms carried into every time history.
        self.eps = 2.5e-3 / vmax.sqrt().max(1.0);
        let (eps, n) = (self.eps, q.len());
        for (k, h) in STEPS.iter().map(|m| m * eps).enumerate() {
            self.dq.clear();
            self.dq.extend(v.iter().zip(a).map(|(v, a)| h * v + 0.5 * h * h * a));
            self.q[k + 1].resize(n, 0.0);
            let (head, tail) = self.q.split_at_mut(1);
            model.retract_inplace(&head[0], &self.dq, &mut tail[k]);
        }
    }

    /// The exact motions of the stations `at` into `motions`, when the model gives them.
    fn exact_motions<S: Structure + ?Sized>(&mut self, model: &S, at: &[(usize, f64)]) -> bool {
        self.moving && self.exact && model.section_motions(&self.q[0], &self.v, &self.a, at, &mut self.motions)
    }

    fn kinematics<S: Structure + ?Sized>(&mut self, model: &S, body: usize, s: f64) -> Kinematics {
        if self.exact_motions(model, &[(body, s)]) {
            return Kinematics::from_motion(&self.motions[0]);
        }
        if self.moving && !self.probes {
            self.make_probes(model);
        }
        let n = if self.moving { 5 } else { 1 };
        let mut poses = [(Vector3::zeros(), Matrix3::zeros()); 5];
        for (pose, q) in poses.iter_mut().zip(&self.q).take(n) {
            *pose = model.section_pose(q, body, s);
        }
        self.differentiate(&poses)
    }

    /// The section's kinematics from its poses at the states `q`, `q(±ε)`, `q(±2ε)` (only the
    /// first when at rest).
    fn differentiate(&self, poses: &[(Vector3<f64>, Matrix3<f64>); 5]) -> Kinematics {
        let (p, r) = poses[0];
        if !self.moving {
            return Kinematics {
                p,
                r,
                acc: Vector3::zeros(),
                r_dd: Matrix3::zeros(),
                omega: Vector3::zeros(),
                alpha: Vector3::zeros(),
            };
        }
        let [_, (p1, r1), (m1, rm1), (p2, r2), (m2, rm2)] = *poses;
        let e = self.eps;
        // Five-point central differences: second and first derivatives, O(ε⁴).
        let acc = (16.0 * (p1 + m1) - (p2 + m2) - 30.0 * p) / (12.0 * e * e);
        let r_dd = (16.0 * (r1 + rm1) - (r2 + rm2) - 30.0 * r) / (12.0 * e * e);
        let w = (8.0 * (r1 - rm1) - (r2 - rm2)) * r.transpose() / (12.0 * e);
        let omega = axial(&w);
        let alpha = axial(&(r_dd * r.transpose()));
        Kinematics { p, r, acc, r_dd, omega, alpha }
    }

    /// The points of the aerodynamic station loads `aero` at `q`, once per evaluation.
    fn ensure_aero_points<S: Structure + ?Sized>(&mut self, model: &S, aero: &[SectionLoad]) {
        if self.aero_ready {
            return;
        }
        self.at.clear();
        self.at.extend(aero.iter().map(|l| (l.body, l.s)));
        model.section_poses(&self.q[0], &self.at, &mut self.poses[0]);
        self.aero_points.clear();
        self.aero_points.extend(self.poses[0].iter().map(|(p, _)| *p));
        self.aero_ready = true;
    }

    /// Body `b`'s kinematics at its Gauss points, once per evaluation (the poses of every
    /// state through [`Structure::section_poses`]).
    fn ensure_gauss<S: Structure + ?Sized>(&mut self, model: &S, b: usize, bm: &BodyMass) {
        if self.gauss.len() <= b {
            self.gauss.resize_with(b + 1, Vec::new);
        }
        if !self.gauss[b].is_empty() {
            return;
        }
        let h = bm.length / bm.n_elements as f64;
        let mut at = std::mem::take(&mut self.at);
        at.clear();
        at.extend((0..bm.n_elements).flat_map(|e| GAUSS3.map(|(xi, _)| (b, h * (e as f64 + xi)))));
        let exact = self.exact_motions(model, &at);
        self.at = at;
        if exact {
            let mut gauss = std::mem::take(&mut self.gauss[b]);
            gauss.extend(self.motions.iter().map(Kinematics::from_motion));
            self.gauss[b] = gauss;
            return;
        }
        if self.moving && !self.probes {
            self.make_probes(model);
        }
        let n = if self.moving { 5 } else { 1 };
        for k in 0..n {
            model.section_poses(&self.q[k], &self.at, &mut self.poses[k]);
        }
        let mut gauss = std::mem::take(&mut self.gauss[b]);
        for i in 0..self.at.len() {
            let mut poses = [(Vector3::zeros(), Matrix3::zeros()); 5];
            for (pose, k) in poses.iter_mut().zip(0..n) {
                *pose = self.poses[k][i];
            }
            gauss.push(self.differentiate(&poses));
        }
        self.gauss[b] = gauss;
    }
}

/// Axial vector of the skew part of `w`.
fn axial(w: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(w[(2, 1)] - w[(1, 2)], w[(0, 2)] - w[(2, 0)], w[(1, 0)] - w[(0, 1)]) * 0.5
}
