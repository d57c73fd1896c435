//! The assembled multibody model: bodies of two-node elements, linear joints, loads, and its
//! two presentations to the integrator (index-3 DAE or reduced ODE).

use crate::Energies;
use crate::elastic_force::{ElementMatrix, LaneMatrix, mirror_upper_inplace};
use crate::element::Element;
use crate::frame::{fold_angle, section_frame, section_frame_motion, section_frame_rate};
use crate::hinge_spring::{Hessian, HingeSpring, Kinematics};
use crate::joint::{ConstraintRow, Joint, node_vector};
use crate::loads::{PointLoad, Station, add_moment_force, add_point_force, locate, moment_tangent};
use crate::mass::nonzeros;
use crate::node_tie::{NodeTie, TieMatrix};
use crate::point_mass::{PointInertia, point_mass_matrix, point_mass_weights};
use crate::reduction::Reduction;
use crate::shape::{ELEMENT_DOF, NODE_DOF, point_weights};
use crate::strain::twisted_reference_element;
use crate::thrust::Thrust;
use crate::{BodySpec, Error, ForceElement, JointSpec, Options, Scene, SolvePath};
use genalpha::{ConstrainedSystem, MatView, State};
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// A body with its place in the global coordinate vector.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Body {
    pub spec: BodySpec,
    /// First global coordinate of the body.
    pub offset: usize,
    pub n_nodes: usize,
    /// The kernel of every element (mass, strain plan with the straight reference).
    pub element: Element,
    /// A twisted body's kernels, one per element, with the twisted reference strains
    /// (docs/ancf.md §1); empty for an untwisted body, whose elements all use `element`.
    pub twisted: Vec<Element>,
}

impl Body {
    pub(crate) fn n_elements(&self) -> usize {
        self.n_nodes - 1
    }

    /// The elastic kernel of element `k`.
    #[inline]
    pub(crate) fn kernel(&self, k: usize) -> &Element {
        self.twisted.get(k).unwrap_or(&self.element)
    }

    /// The reference section frame (columns x, y, z, global) at node `n`.
    pub(crate) fn node_frame(&self, n: usize) -> Matrix3<f64> {
        self.spec.section_frame(n as f64 * self.element.l)
    }
}

#[derive(Debug, Clone, PartialEq)]
struct Workspace {
    q: Vec<f64>,
    v: Vec<f64>,
    r: Vec<f64>,
    /// Full velocities (ODE path, for the hinge dampers).
    rate: Vec<f64>,
}

/// An element with dependent coordinates on the ODE path: its matrix `k_e` enters the reduced
/// coordinates as `Rᵀ k_e R` over the (sorted) independent indices `z` it reaches; `rows[a]` lists
/// `(position in z, coefficient)` of local coordinate `a`.
#[derive(Debug, Clone)]
struct ReducedElement {
    z: Vec<usize>,
    rows: Vec<Vec<(usize, f64)>>,
}

/// The ANCF multibody model. Implements [`genalpha::ConstrainedSystem`] in the form chosen by
/// [`Options::path`]:
///
/// * [`SolvePath::Dae`]: `q` = all nodal coordinates, `M q̈ + f_el(q) + f_s(q, q̇) − Q + Φ_qᵀ λ = 0`,
///   `Φ(q) = Φ_q q − c = 0` with the constant `Φ_q`; `f_s = Σ (k(θ−θ₀) + c θ̇) θ_q` of the
///   hinge springs and dampers, `M` constant with the point masses and centre-of-mass offsets.
/// * [`SolvePath::Ode`]: `q` = the independent coordinates `z`, `q_full = B z + q_p`,
///   `BᵀMB z̈ + Bᵀ(f_el + f_s − Q) = 0`.
///
/// Every method taking `q` (or `v`) expects the vector of the chosen form, as the integrator
/// holds it.
#[derive(Debug)]
pub struct Model {
    pub(crate) bodies: Vec<Body>,
    pub(crate) joints: Vec<Joint>,
    rows: Vec<ConstraintRow>,
    pub(crate) reduction: Reduction,
    options: Options,
    gravity: Vector3<f64>,
    n_full: usize,
    q_ref: Vec<f64>,
    gravity_force: Vec<f64>,
    point_force: Vec<f64>,
    moments: Vec<(Station, Vector3<f64>)>,
    load_factor: f64,
    weights: Vec<f64>,
    /// Per element (bodies in order): z index of its first coordinate when all 24 are
    /// independent and hence contiguous in z.
    element_z: Vec<Option<usize>>,
    /// Per element whose `element_z` is `None`: how its matrix reaches the reduced coordinates.
    element_reduced: Vec<Option<ReducedElement>>,
    /// The reduced matrix of an element with dependent coordinates (ODE path), n_z × n_z.
    reduced_block: Mutex<Vec<f64>>,
    /// Full-coordinate buffers of the ODE path's residual and matrix.
    work: Mutex<Workspace>,
    /// Full coordinates, velocities and accelerations of the sensors on the ODE path.
    sensor: Mutex<(Vec<f64>, Vec<f64>, Vec<f64>)>,
    /// Whether the iteration matrix is symmetric (no follower moments; a hinge damper's
    /// unsymmetric term is left out of Newton's matrix and vanishes at rest), shared with the
    /// [`SkylineLu`](crate::SkylineLu)s of [`linear_solver`](Self::linear_solver).
    symmetric: Arc<AtomicBool>,
    /// Hinge springs and dampers (docs/ancf.md §11).
    springs: Vec<HingeSpring>,
    /// Whether a spring has damping (the residual then reads the velocities).
    damped: bool,
    /// Thrusts, follower forces (docs/ancf.md §14).
    thrusts: Vec<Thrust>,
    /// Point masses (docs/ancf.md §12.2), each on its element.
    point_inertia: Vec<PointInertia>,
    /// Section ties at the joint nodes whose axis equation involves `r_x` (docs/ancf.md §3.5).
    ties: Vec<NodeTie>,
}

impl Model {
    /// Validate the scene and build the model (constant mass, element kernels, constraint
    /// equations, elimination basis). Errors name the offending field. A scene without force
    /// elements; see [`from_scene`](Self::from_scene).
    pub fn new(
        bodies: &[BodySpec],
        joints: &[JointSpec],
        gravity: Vector3<f64>,
        options: Options,
    ) -> Result<Model, Error> {
        Self::from_scene(&Scene::new(bodies.to_vec(), joints.to_vec(), gravity), options)
    }

    /// Validate the scene and build the model. Errors name the offending field.
    pub fn from_scene(scene: &Scene, options: Options) -> Result<Model, Error> {
        scene.validate()?;
        options.validate()?;
        let (bodies, joints, gravity) = (&scene.bodies, &scene.joints, scene.gravity);

        let mut offset = 0;
        let bodies: Vec<Body> = bodies
            .iter()
            .map(|spec| {
                let l = spec.length / spec.n_elements as f64;
                let element = Element::new(l, &spec.section, options.curvature, options.penalty_factor);
                let twisted = if spec.twist.is_none() {
                    Vec::new()
                } else {
                    let theta = |n: usize| spec.twist.angle(n as f64 * l);
                    (0..spec.n_elements)
                        .map(|k| element.with_reference(&twisted_reference_element(l, theta(k), theta(k + 1))))
                        .collect()
                };
                let b = Body { spec: spec.clone(), offset, n_nodes: spec.n_elements + 1, element, twisted };
                offset += NODE_DOF * b.n_nodes;
                b
            })
            .collect();
        let n_full = offset;

        let mut q_ref = vec![0.0; n_full];
        let mut weights = vec![1.0; n_full];
        for b in &bodies {
            for n in 0..b.n_nodes {
                let f = b.node_frame(n);
                let i = b.offset + NODE_DOF * n;
                let r = b.spec.start + b.spec.frame.column(0) * (n as f64 * b.element.l);
                for k in 0..3 {
                    q_ref[i + k] = r[k];
                    q_ref[i + 3 + k] = f[(k, 0)];
                    q_ref[i + 6 + k] = f[(k, 1)];
                    q_ref[i + 9 + k] = f[(k, 2)];
                }
                weights[i + 3..i + 12].iter_mut().for_each(|w| *w = b.element.l);
            }
        }

        let joint_list: Vec<Joint> = joints.iter().map(|s| Joint::new(s, &bodies)).collect();
        let rows: Vec<ConstraintRow> = joint_list.iter().enumerate().flat_map(|(j, jt)| jt.rows(j, &bodies)).collect();
        let reduction = Reduction::new(&rows, n_full)?;

        let mut gravity_force = vec![0.0; n_full];
        let g = [gravity.x, gravity.y, gravity.z];
        for b in &bodies {
            let fe = b.element.gravity_force(g);
            for k in 0..b.n_elements() {
                let first = b.offset + NODE_DOF * k;
                for (x, y) in gravity_force[first..first + ELEMENT_DOF].iter_mut().zip(&fe) {
                    *x += y;
                }
            }
        }

        // Point masses: their mass on their element, their weight at their centre.
        let mut point_inertia = Vec::new();
        let mut elements_before = 0;
        for b in &bodies {
            for p in &b.spec.point_masses {
                let st = locate(b, p.at);
                let w = point_mass_weights(p, st.xi, st.l);
                for (k, wk) in w.iter().enumerate() {
                    for i in 0..3 {
                        gravity_force[st.first + 3 * k + i] += p.mass * wk * g[i];
                    }
                }
                point_inertia.push(PointInertia {
                    e_index: elements_before + (st.first - b.offset) / NODE_DOF,
                    first: st.first,
                    mass_nz: nonzeros(&point_mass_matrix(p, st.xi, st.l)),
                });
            }
            elements_before += b.n_elements();
        }

        let (springs, thrusts) = force_elements(&scene.forces, &joint_list, &bodies, &q_ref);
        let damped = springs.iter().any(|s| s.damping != 0.0);
        let ties = joint_ties(&joint_list, &bodies, options.joint_tie_factor);

        let mut element_z = Vec::new();
        let mut element_reduced = Vec::new();
        for b in &bodies {
            for k in 0..b.n_elements() {
                let first = b.offset + NODE_DOF * k;
                let z0 = reduction.z_of(first);
                let contiguous =
                    z0.is_some_and(|z0| (0..ELEMENT_DOF).all(|a| reduction.z_of(first + a) == Some(z0 + a)));
                element_z.push(if contiguous { z0 } else { None });
                element_reduced.push((!contiguous).then(|| {
                    let mut z: Vec<usize> =
                        (first..first + ELEMENT_DOF).flat_map(|a| reduction.row(a).iter().map(|&(z, _)| z)).collect();
                    z.sort_unstable();
                    z.dedup();
                    let rows = (first..first + ELEMENT_DOF)
                        .map(|a| {
                            let pos = |zi: usize| z.binary_search(&zi).expect("z collected above");
                            reduction.row(a).iter().map(|&(zi, c)| (pos(zi), c)).collect()
                        })
                        .collect();
                    ReducedElement { z, rows }
                }));
            }
        }
        let max_reduced = element_reduced.iter().flatten().map(|e| e.z.len()).max().unwrap_or(0);

        let n_red = reduction.n_reduced();
        Ok(Model {
            bodies,
            joints: joint_list,
            rows,
            reduction,
            options,
            gravity,
            n_full,
            q_ref,
            gravity_force,
            point_force: vec![0.0; n_full],
            moments: Vec::new(),
            load_factor: 1.0,
            weights,
            element_z,
            element_reduced,
            reduced_block: Mutex::new(vec![0.0; max_reduced * max_reduced]),
            work: Mutex::new(Workspace {
                q: vec![0.0; n_full],
                v: vec![0.0; n_full],
                r: vec![0.0; n_full],
                rate: vec![0.0; if damped { n_full } else { 0 }],
            }),
            sensor: Mutex::new((vec![0.0; n_full], vec![0.0; n_full.max(n_red)], vec![0.0; n_full])),
            // a follower force's tangent is unsymmetric
            symmetric: Arc::new(AtomicBool::new(thrusts.is_empty())),
            springs,
            damped,
            thrusts,
            point_inertia,
            ties,
        })
    }

    /// The options the model was built with.
    pub fn options(&self) -> &Options {
        &self.options
    }
    /// Gravity vector, m/s².
    pub fn gravity(&self) -> Vector3<f64> {
        self.gravity
    }
    /// Number of nodal coordinates (12 per node).
    pub fn n_full_coords(&self) -> usize {
        self.n_full
    }
    /// Number of independent coordinates of the ODE form.
    pub fn n_reduced_coords(&self) -> usize {
        self.reduction.n_reduced()
    }
    /// Number of joint equations.
    pub fn n_constraint_rows(&self) -> usize {
        self.rows.len()
    }
    /// Number of bodies.
    pub fn n_bodies(&self) -> usize {
        self.bodies.len()
    }
    /// Number of joints.
    pub fn n_joints(&self) -> usize {
        self.joints.len()
    }
    /// The body specifications.
    pub fn body_spec(&self, body: usize) -> Option<&BodySpec> {
        self.bodies.get(body).map(|b| &b.spec)
    }
    /// Total length of all bodies (m).
    pub fn span(&self) -> f64 {
        self.bodies.iter().map(|b| b.spec.length).sum()
    }
    /// Reference nodal coordinates (full form).
    pub fn reference_coordinates(&self) -> &[f64] {
        &self.q_ref
    }

    /// A generalized-α integrator for this model with the [`SkylineLu`](crate::SkylineLu)
    /// linear solver set up for the model's sparsity (banded ANCF matrices; several times
    /// faster than the dense default).
    pub fn integrator(
        &self,
        params: genalpha::IntegratorParams,
    ) -> Result<genalpha::GenAlpha<crate::SkylineLu>, genalpha::Error> {
        genalpha::GenAlpha::with_solver(params, self, self.linear_solver())
    }

    /// Coordinates coupled through the iteration matrix (symmetric adjacency, integrator layout:
    /// coordinates then multipliers).
    fn adjacency(&self) -> Vec<Vec<usize>> {
        let n = self.n_dof();
        let n_all = n + self.n_holonomic();
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n_all];
        let mut set = Vec::with_capacity(3 * ELEMENT_DOF);
        for b in &self.bodies {
            for el in 0..b.n_elements() {
                let first = b.offset + NODE_DOF * el;
                set.clear();
                for a in first..first + ELEMENT_DOF {
                    match self.options.path {
                        SolvePath::Dae => set.push(a),
                        SolvePath::Ode => set.extend(self.reduction.row(a).iter().map(|&(z, _)| z)),
                    }
                }
                for &i in &set {
                    adj[i].extend_from_slice(&set);
                }
            }
        }
        for spring in &self.springs {
            let (idx, n) = spring.coordinates();
            set.clear();
            for &a in &idx[..n] {
                match self.options.path {
                    SolvePath::Dae => set.push(a),
                    SolvePath::Ode => set.extend(self.reduction.row(a).iter().map(|&(z, _)| z)),
                }
            }
            for &i in &set {
                adj[i].extend_from_slice(&set);
            }
        }
        if self.options.path == SolvePath::Dae {
            for (r, row) in self.rows.iter().enumerate() {
                for &(col, _) in &row.entries {
                    adj[n + r].push(col);
                    adj[col].push(n + r);
                }
            }
        }
        for list in &mut adj {
            list.sort_unstable();
            list.dedup();
        }
        adj
    }

    /// A [`SkylineLu`](crate::SkylineLu) that knows the structure of this model's iteration
    /// matrix (in the integrator's layout: coordinates, then multipliers) and, while no follower
    /// moment is loaded and no hinge has a damper, that its values are symmetric (see
    /// [`SkylineLu::with_symmetry_hint`](crate::SkylineLu::with_symmetry_hint)).
    pub fn linear_solver(&self) -> crate::SkylineLu {
        crate::SkylineLu::with_structure(self.n_dof(), self.adjacency()).with_symmetry_hint(Arc::clone(&self.symmetric))
    }

    /// The undeformed reference configuration at rest, sized for genalpha.
    pub fn initial_state(&self) -> State {
        let q0 = match self.options.path {
            SolvePath::Dae => self.q_ref.clone(),
            SolvePath::Ode => self.reduction.restrict(&self.q_ref),
        };
        State::at_rest(self, 0.0, q0)
    }

    /// Full nodal coordinates from the model's coordinate vector (identity on the DAE path,
    /// `B z + q_p` on the ODE path).
    ///
    /// # Panics
    /// When the lengths do not match the model.
    pub fn full_coordinates_inplace(&self, q: &[f64], out: &mut [f64]) {
        assert_eq!(out.len(), self.n_full, "full coordinate buffer has the wrong length");
        match self.options.path {
            SolvePath::Dae => out.copy_from_slice(q),
            SolvePath::Ode => self.reduction.expand_inplace(q, out),
        }
    }
    /// Full nodal velocities from the model's velocity vector.
    ///
    /// # Panics
    /// When the lengths do not match the model.
    pub fn full_velocities_inplace(&self, v: &[f64], out: &mut [f64]) {
        assert_eq!(out.len(), self.n_full, "full velocity buffer has the wrong length");
        match self.options.path {
            SolvePath::Dae => out.copy_from_slice(v),
            SolvePath::Ode => self.reduction.expand_rate_inplace(v, out),
        }
    }
    /// Allocating form of [`full_coordinates_inplace`](Self::full_coordinates_inplace).
    pub fn full_coordinates(&self, q: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.n_full];
        self.full_coordinates_inplace(q, &mut out);
        out
    }

    /// Run `f` on the full coordinates of `q` without allocating.
    fn with_full<R>(&self, q: &[f64], f: impl FnOnce(&[f64]) -> R) -> R {
        match self.options.path {
            SolvePath::Dae => f(q),
            SolvePath::Ode => {
                let mut s = scratch(&self.sensor);
                self.reduction.expand_inplace(q, &mut s.0);
                f(&s.0)
            }
        }
    }

    /// Centroid of the free end section of the last body (global, m).
    pub fn tip_position(&self, q: &[f64]) -> Vector3<f64> {
        self.with_full(q, |q| {
            let b = self.bodies.last().expect("a model has at least one body");
            node_vector(b, q, b.n_nodes - 1, 0)
        })
    }

    /// Fold angle θ (rad) of joint `joint`, which must be a flared hinge: the rotation of the
    /// child's start section frame relative to the parent's end section frame (reference
    /// value removed) about `−a`; θ > 0 lifts the child's free end toward +z of the parent's
    /// section for β < 90°.
    pub fn fold_angle(&self, q: &[f64], joint: usize) -> Result<f64, Error> {
        let jt = self.joints.get(joint).ok_or(Error::NoSuchJoint { joint, n_joints: self.joints.len() })?;
        let Joint::Flared { parent, child, alpha_p, rel0, .. } = jt else {
            return Err(Error::NotAFlaredHinge { joint });
        };
        Ok(self.with_full(q, |q| {
            let (p, c) = (&self.bodies[*parent], &self.bodies[*child]);
            let pe = p.n_nodes - 1;
            let rp = section_frame(&node_vector(p, q, pe, 2), &node_vector(p, q, pe, 3));
            let rc = section_frame(&node_vector(c, q, 0, 2), &node_vector(c, q, 0, 3));
            fold_angle(&(rp.transpose() * rc * rel0.transpose()), alpha_p)
        }))
    }

    /// Kinetic, elastic and gravitational potential energy.
    pub fn energies(&self, q: &[f64], v: &[f64]) -> Energies {
        let mut s = scratch(&self.sensor);
        let (qf, vf, _) = &mut *s;
        self.full_coordinates_inplace(q, qf);
        self.full_velocities_inplace(v, &mut vf[..self.n_full]);
        let mut e = Energies::default();
        let mut mv = [0.0; ELEMENT_DOF];
        for b in &self.bodies {
            for k in 0..b.n_elements() {
                let first = b.offset + NODE_DOF * k;
                let range = first..first + ELEMENT_DOF;
                mv.iter_mut().for_each(|x| *x = 0.0);
                b.element.add_mass_times(1.0, &vf[range.clone()], &mut mv);
                e.kinetic += 0.5 * mv.iter().zip(&vf[range.clone()]).map(|(a, b)| a * b).sum::<f64>();
                e.elastic += b.kernel(k).elastic_energy(&qf[range]);
            }
        }
        for p in &self.point_inertia {
            let range = p.first..p.first + ELEMENT_DOF;
            mv.iter_mut().for_each(|x| *x = 0.0);
            p.add_mass_times(1.0, &vf[range.clone()], &mut mv);
            e.kinetic += 0.5 * mv.iter().zip(&vf[range]).map(|(a, b)| a * b).sum::<f64>();
        }
        e.elastic += self.ties.iter().map(|t| t.energy(qf)).sum::<f64>();
        e.spring = self.springs.iter().map(|s| s.energy(qf)).sum();
        e.potential =
            -self.gravity_force.iter().zip(qf.iter().zip(&self.q_ref)).map(|(g, (q, q0))| g * (q - q0)).sum::<f64>();
        e
    }

    /// Linear momentum and angular momentum about the global origin (docs/ancf.md §13).
    ///
    /// With the constant mass matrix `M` and the kinetic energy `½ q̇ᵀ M q̇`, they are the
    /// momentum map of the rigid motions: a translation `u` moves every node's position by `u`
    /// and no slope, a rotation `ω` turns every nodal vector `e` (position and slopes) into
    /// `ω × e`, and the field `r = S(x) e` follows exactly because it is linear in the nodal
    /// vectors. So `p = Σ_nodes (M q̇)_r` and `L = Σ_vectors e × (M q̇)_e`, element by element
    /// and over the point masses: the momenta the discrete equations of motion balance.
    pub fn momentum(&self, q: &[f64], v: &[f64]) -> formulation::Momentum {
        let mut s = scratch(&self.sensor);
        let (qf, vf, _) = &mut *s;
        self.full_coordinates_inplace(q, qf);
        self.full_velocities_inplace(v, &mut vf[..self.n_full]);
        let mut out = formulation::Momentum::default();
        let mut mv = [0.0; ELEMENT_DOF];
        let mut add = |first: usize, mv: &[f64; ELEMENT_DOF]| {
            for b in 0..ELEMENT_DOF / 3 {
                let m = Vector3::new(mv[3 * b], mv[3 * b + 1], mv[3 * b + 2]);
                let i = first + 3 * b;
                out.angular += Vector3::new(qf[i], qf[i + 1], qf[i + 2]).cross(&m);
                if b % 4 == 0 {
                    out.linear += m;
                }
            }
        };
        for b in &self.bodies {
            for k in 0..b.n_elements() {
                let first = b.offset + NODE_DOF * k;
                mv.iter_mut().for_each(|x| *x = 0.0);
                b.element.add_mass_times(1.0, &vf[first..first + ELEMENT_DOF], &mut mv);
                add(first, &mv);
            }
        }
        for p in &self.point_inertia {
            mv.iter_mut().for_each(|x| *x = 0.0);
            p.add_mass_times(1.0, &vf[p.first..p.first + ELEMENT_DOF], &mut mv);
            add(p.first, &mv);
        }
        out
    }

    /// `out = M v` for full velocities `v` (the constant mass of the elements and point
    /// masses), `out` overwritten.
    pub(crate) fn mass_times_full(&self, v: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        for b in &self.bodies {
            for k in 0..b.n_elements() {
                let range = b.offset + NODE_DOF * k..b.offset + NODE_DOF * k + ELEMENT_DOF;
                b.element.add_mass_times(1.0, &v[range.clone()], &mut out[range]);
            }
        }
        for p in &self.point_inertia {
            let range = p.first..p.first + ELEMENT_DOF;
            p.add_mass_times(1.0, &v[range.clone()], &mut out[range]);
        }
    }

    /// Power dissipated by the hinge dampers `Σ c θ̇²`, W (≥ 0), at coordinates `q` and
    /// velocities `v` of the model's form. Its time integral is the work the dampers took out
    /// of `T + U + V + spring energy`.
    pub fn dissipation_power(&self, q: &[f64], v: &[f64]) -> f64 {
        if !self.damped {
            return 0.0;
        }
        let mut s = scratch(&self.sensor);
        let (qf, vf, _) = &mut *s;
        self.full_coordinates_inplace(q, qf);
        self.full_velocities_inplace(v, &mut vf[..self.n_full]);
        self.springs
            .iter()
            .filter(|sp| sp.damping != 0.0)
            .map(|sp| {
                let rate = HingeSpring::rate(&sp.kinematics(qf, false), vf);
                sp.damping * rate * rate
            })
            .sum()
    }

    /// Hinge angle θ (rad) of joint `joint`, a ground hinge or a free flared hinge, as the hinge
    /// springs measure it (docs/ancf.md §11): for a flared hinge the fold angle (about `−a`, as
    /// [`fold_angle`](Self::fold_angle), equal to it for orthonormal section slopes), for a
    /// ground hinge the rotation of the body's start section about the fixed axis (right-hand
    /// rule), both zero in the reference configuration. On a joint with a spring the angle is
    /// unwrapped against the last accepted step (it keeps counting past ±π); on other joints
    /// it is in [−π, π).
    pub fn hinge_angle(&self, q: &[f64], joint: usize) -> Result<f64, Error> {
        let jt = self.joints.get(joint).ok_or(Error::NoSuchJoint { joint, n_joints: self.joints.len() })?;
        if !matches!(jt, Joint::Ground { .. } | Joint::Flared { lock: None, .. }) {
            return Err(Error::NotAFreeHinge { joint });
        }
        Ok(self.with_full(q, |q| match self.springs.iter().find(|s| s.joint == joint) {
            Some(s) => s.angle(q),
            None => HingeSpring::new(joint, jt, &self.bodies, 0.0, 0.0, 0.0).angle(q),
        }))
    }

    /// Rate of the hinge angle of [`hinge_angle`](Self::hinge_angle), rad/s, at `q`, `v` (the
    /// model's form): the angle's gradient times the full velocities.
    pub fn hinge_rate(&self, q: &[f64], v: &[f64], joint: usize) -> Result<f64, Error> {
        let jt = self.joints.get(joint).ok_or(Error::NoSuchJoint { joint, n_joints: self.joints.len() })?;
        if !matches!(jt, Joint::Ground { .. } | Joint::Flared { lock: None, .. }) {
            return Err(Error::NotAFreeHinge { joint });
        }
        let hinge = HingeSpring::new(joint, jt, &self.bodies, 0.0, 0.0, 0.0);
        let mut s = scratch(&self.sensor);
        let (qf, vf, _) = &mut *s;
        self.full_coordinates_inplace(q, qf);
        self.full_velocities_inplace(v, &mut vf[..self.n_full]);
        Ok(HingeSpring::rate(&hinge.kinematics(qf, false), vf))
    }

    /// Restart the hinge springs' angle unwrapping at `q` (the model's form): each spring's
    /// angle becomes its principal value in [−π, π). Call it before integrating from a state
    /// that is not the continuation of the model's last step (a model reused for a new run, or
    /// a start away from the reference configuration); after every accepted step
    /// [`post_step`](ConstrainedSystem::post_step) unwraps against the previous angle instead.
    pub fn reset_hinge_angles(&mut self, q: &[f64]) {
        if self.springs.is_empty() {
            return;
        }
        self.springs.iter_mut().for_each(HingeSpring::forget);
        self.accept_hinge_angles(q);
    }

    /// The angles at `q` (the model's form) become the springs' unwrapping reference.
    fn accept_hinge_angles(&mut self, q: &[f64]) {
        let Model { springs, work, reduction, options, .. } = self;
        match options.path {
            SolvePath::Dae => springs.iter_mut().for_each(|s| s.accept(q)),
            SolvePath::Ode => {
                let qf = &mut work.get_mut().unwrap_or_else(PoisonError::into_inner).q;
                reduction.expand_inplace(q, qf);
                springs.iter_mut().for_each(|s| s.accept(qf));
            }
        }
    }

    /// Position-level joint violation: the Euclidean norm over all joints of (position gap in m,
    /// axis misalignment angle in rad; for clamps the full relative rotation angle).
    pub fn constraint_residual(&self, q: &[f64]) -> f64 {
        self.with_full(q, |q| {
            self.joints
                .iter()
                .map(|j| {
                    let (gap, angle) = j.violation(&self.bodies, q);
                    gap * gap + angle * angle
                })
                .sum::<f64>()
                .sqrt()
        })
    }

    /// Check a station; `field` names the input (formatted only on error: no allocation on
    /// the valid path).
    fn check_station(&self, field: impl Fn() -> String, body: usize, s: f64) -> Result<&Body, Error> {
        let b = self.bodies.get(body).ok_or_else(|| Error::NoSuchBody {
            field: format!("{}.body", field()),
            body,
            n_bodies: self.bodies.len(),
        })?;
        if !s.is_finite() {
            return Err(Error::NonFinite { field: format!("{}.s", field()), value: s });
        }
        let len = b.spec.length;
        if s < -1e-12 * len || s > len * (1.0 + 1e-12) {
            return Err(Error::ArclengthOutOfRange { field: format!("{}.s", field()), s, length: len });
        }
        Ok(b)
    }

    /// Position (global, m) of the material point with section coordinates (y, z) at arclength
    /// `s` of `body`: `S(x, y, z) q`.
    pub fn material_point(&self, q: &[f64], body: usize, s: f64, y: f64, z: f64) -> Result<Vector3<f64>, Error> {
        let b = self.check_station(|| "station".to_string(), body, s)?;
        let st = locate(b, s);
        Ok(self.with_full(q, |q| {
            let w = point_weights(st.xi, st.l, y, z);
            (0..8)
                .map(|k| Vector3::new(q[st.first + 3 * k], q[st.first + 3 * k + 1], q[st.first + 3 * k + 2]) * w[k])
                .sum()
        }))
    }

    /// Velocity (global, m/s) of the material point (s, y, z) of `body`: `S(x, y, z) q̇`.
    pub fn material_velocity(&self, v: &[f64], body: usize, s: f64, y: f64, z: f64) -> Result<Vector3<f64>, Error> {
        let b = self.check_station(|| "station".to_string(), body, s)?;
        let st = locate(b, s);
        let mut sens = scratch(&self.sensor);
        let vf = &mut sens.1[..self.n_full];
        self.full_velocities_inplace(v, vf);
        let w = point_weights(st.xi, st.l, y, z);
        Ok((0..8)
            .map(|k| Vector3::new(vf[st.first + 3 * k], vf[st.first + 3 * k + 1], vf[st.first + 3 * k + 2]) * w[k])
            .sum())
    }

    /// Axis point (global, m) and orthonormalised section frame (columns x, y, z) at arclength
    /// `s` of `body`.
    pub fn section_frame(&self, q: &[f64], body: usize, s: f64) -> Result<(Vector3<f64>, Matrix3<f64>), Error> {
        let b = self.check_station(|| "station".to_string(), body, s)?;
        let st = locate(b, s);
        Ok(self.with_full(q, |q| {
            let w = point_weights(st.xi, st.l, 0.0, 0.0);
            let v = |k: usize| Vector3::new(q[st.first + 3 * k], q[st.first + 3 * k + 1], q[st.first + 3 * k + 2]);
            let r: Vector3<f64> = (0..8).map(|k| v(k) * w[k]).sum();
            let ry = v(2) * (1.0 - st.xi) + v(6) * st.xi;
            let rz = v(3) * (1.0 - st.xi) + v(7) * st.xi;
            (r, section_frame(&ry, &rz))
        }))
    }

    /// Axis point, section frame, the point's velocity and the frame's angular velocity (global)
    /// of each `(body, s)` of `at` at coordinates `q` and velocities `v`, into `out` (cleared
    /// first): the point and the slopes interpolate the nodal vectors linearly, so their rates
    /// interpolate the nodal velocities (both paths' full coordinates are linear in the model's),
    /// and the frame's rate is that of its polar factor ([`section_frame_rate`]).
    pub fn section_states(
        &self,
        q: &[f64],
        v: &[f64],
        at: &[(usize, f64)],
        out: &mut Vec<formulation::SectionState>,
    ) -> Result<(), Error> {
        out.clear();
        let mut guard = scratch(&self.sensor);
        let (qf, vf, _) = &mut *guard;
        let (qf, vf) = (&mut qf[..self.n_full], &mut vf[..self.n_full]);
        self.full_coordinates_inplace(q, qf);
        self.full_velocities_inplace(v, vf);
        self.each_station(at, [qf, vf], |[(p, ry, rz), (dp, dry, drz)]| {
            let (r, omega) = section_frame_rate(&ry, &rz, &dry, &drz);
            out.push((p, r, dp, omega));
        })
    }

    /// [`section_states`](Self::section_states) with the accelerations: at coordinates `q`,
    /// velocities `v` and accelerations `a` (`v̇`; on both paths the full accelerations are
    /// linear in them), the axis point's acceleration interpolates the nodal accelerations and
    /// the frame's angular acceleration is its polar factor's ([`section_frame_motion`]).
    pub fn section_motions(
        &self,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        at: &[(usize, f64)],
        out: &mut Vec<formulation::SectionMotion>,
    ) -> Result<(), Error> {
        out.clear();
        let mut guard = scratch(&self.sensor);
        let (qf, vf, af) = &mut *guard;
        let (qf, vf, af) = (&mut qf[..self.n_full], &mut vf[..self.n_full], &mut af[..self.n_full]);
        self.full_coordinates_inplace(q, qf);
        self.full_velocities_inplace(v, vf);
        self.full_velocities_inplace(a, af);
        self.each_station(at, [qf, vf, af], |[(p, ry, rz), (dp, dry, drz), (ddp, ddry, ddrz)]| {
            let (r, omega, alpha) = section_frame_motion(&ry, &rz, &dry, &drz, &ddry, &ddrz);
            out.push(formulation::SectionMotion { p, r, vel: dp, omega, acc: ddp, alpha });
        })
    }

    /// For each station of `at`, the axis point and the two section slopes interpolated from
    /// each full vector of `xs` (coordinates or their rates: both interpolate alike), handed to
    /// `each`; a station outside the model is an error naming it.
    fn each_station<const N: usize>(
        &self,
        at: &[(usize, f64)],
        xs: [&[f64]; N],
        mut each: impl FnMut([(Vector3<f64>, Vector3<f64>, Vector3<f64>); N]),
    ) -> Result<(), Error> {
        for (i, &(body, s)) in at.iter().enumerate() {
            let b = self.check_station(|| format!("station {i}"), body, s)?;
            let st = locate(b, s);
            let w = point_weights(st.xi, st.l, 0.0, 0.0);
            let at = |x: &[f64], k: usize| {
                Vector3::new(x[st.first + 3 * k], x[st.first + 3 * k + 1], x[st.first + 3 * k + 2])
            };
            let slope = |x: &[f64], k: usize| at(x, k) * (1.0 - st.xi) + at(x, k + 4) * st.xi;
            each(xs.map(|x| ((0..8).map(|k| at(x, k) * w[k]).sum(), slope(x, 2), slope(x, 3))));
        }
        Ok(())
    }

    /// Replace the point loads. Forces are dead loads at material points (constant generalized
    /// forces); moments are fixed global vectors acting on the section (configuration-dependent,
    /// with their tangent). Does not allocate once the moment list has reached its size.
    /// On error the previous loads are kept.
    pub fn set_point_loads(&mut self, loads: &[PointLoad]) -> Result<(), Error> {
        for (i, p) in loads.iter().enumerate() {
            self.check_station(|| format!("loads[{i}]"), p.body, p.s)?;
            let values = [("y", p.y), ("z", p.z)].into_iter().chain((0..3).flat_map(|k| {
                [
                    (["force[0]", "force[1]", "force[2]"][k], p.force[k]),
                    (["moment[0]", "moment[1]", "moment[2]"][k], p.moment[k]),
                ]
            }));
            for (name, x) in values {
                if !x.is_finite() {
                    return Err(Error::NonFinite { field: format!("loads[{i}].{name}"), value: x });
                }
            }
        }
        self.point_force.iter_mut().for_each(|x| *x = 0.0);
        self.moments.clear();
        for p in loads {
            let st = locate(&self.bodies[p.body], p.s);
            if p.force != Vector3::zeros() {
                add_point_force(st, p.y, p.z, &p.force, &mut self.point_force);
            }
            if p.moment != Vector3::zeros() {
                self.moments.push((st, p.moment));
            }
        }
        // a follower moment's tangent is not symmetric; a damper's unsymmetric term vanishes at
        // rest (statics, linearisation) and Newton's matrix of a time step leaves it out; a
        // thrust's tangent is unsymmetric too
        self.symmetric.store(self.moments.is_empty() && self.thrusts.is_empty(), Ordering::Relaxed);
        Ok(())
    }

    /// Factor on all external loads (gravity and point loads), 1 by default; the static solver
    /// ramps it.
    pub fn set_load_factor(&mut self, factor: f64) {
        self.load_factor = factor;
    }
    /// The current load factor.
    pub fn load_factor(&self) -> f64 {
        self.load_factor
    }

    /// Increment weight of full coordinate `i` (1 for positions, the element length for slopes).
    pub(crate) fn full_weight(&self, i: usize) -> f64 {
        self.weights[i]
    }

    /// Constraint equations (full coordinates).
    pub(crate) fn rows(&self) -> &[ConstraintRow] {
        &self.rows
    }

    /// `r = M v̇ + f_el(q) − λ_load (Q_g + Q_F + Q_M(q) + Q_T(t, q))` on full coordinates, with
    /// the hinge springs at rest (`θ̇ = 0`: no damping force).
    pub(crate) fn full_residual(&self, t: f64, q: &[f64], v_dot: &[f64], r: &mut [f64]) {
        self.full_residual_at(t, q, None, v_dot, r);
    }

    /// `r = M v̇ + f_el(q) + Σ (k(θ−θ₀) + cθ̇) θ_q − λ_load (Q_g + Q_F + Q_M(q) + Q_T(t, q))` on
    /// full coordinates, the thrusts `Q_T` at time `t`; `v` (full velocities) is read only by the
    /// dampers (`None`: θ̇ = 0).
    fn full_residual_at(&self, t: f64, q: &[f64], v: Option<&[f64]>, v_dot: &[f64], r: &mut [f64]) {
        let lf = self.load_factor;
        for ((ri, g), p) in r.iter_mut().zip(&self.gravity_force).zip(&self.point_force) {
            *ri = -lf * (g + p);
        }
        for b in &self.bodies {
            let n = b.n_elements();
            let mut k = 0;
            // A twisted body's elements have kernels of their own: one at a time.
            while b.twisted.is_empty() && k + ELEMENT_LANES <= n {
                add_element_residuals::<ELEMENT_LANES>(b, k, q, v_dot, r);
                k += ELEMENT_LANES;
            }
            for k in k..n {
                add_element_residuals::<1>(b, k, q, v_dot, r);
            }
        }
        if !self.moments.is_empty() {
            // r −= λ Q_M: accumulate with the sign flipped through a negated moment.
            for (st, m) in &self.moments {
                add_moment_force(*st, &(-lf * m), q, r);
            }
        }
        for th in &self.thrusts {
            th.add_residual(lf * th.magnitude(t), q, r);
        }
        for p in &self.point_inertia {
            let range = p.first..p.first + ELEMENT_DOF;
            p.add_mass_times(1.0, &v_dot[range.clone()], &mut r[range]);
        }
        for tie in &self.ties {
            tie.add_force(q, r);
        }
        for spring in &self.springs {
            let kin = spring.kinematics(q, false);
            let rate = match v {
                Some(v) if spring.damping != 0.0 => HingeSpring::rate(&kin, v),
                _ => 0.0,
            };
            let m = spring.moment(&kin, rate);
            for a in 0..kin.n {
                r[kin.idx[a]] += m * kin.grad[a];
            }
        }
    }

    /// `k += c_m M + c_c ∂r/∂v + c_k ∂r/∂q` at full coordinates `q` and velocities `v` (`None`:
    /// zero; only the dampers read them), written through the chosen form; with `at_rest`
    /// Newton's matrix of a static iteration (`c_m = c_c = 0`, docs/ancf.md §9).
    #[allow(clippy::too_many_arguments)] // the state, the three generalized-α weights and the kind
    fn add_iteration_matrix(
        &self,
        t: f64,
        q: &[f64],
        v: Option<&[f64]>,
        c_m: f64,
        c_c: f64,
        c_k: f64,
        at_rest: bool,
        k: &mut MatView<'_>,
    ) {
        // With both c_m and c_k it is Newton's matrix of a time step: the section penalties and
        // ties then keep only the positive semidefinite part of their geometric terms
        // (docs/ancf.md §3.4); at rest the transverse shears and compressed axial strains lose
        // theirs too (§9). The analyses ask for M and K_t apart (c_m = 0 or c_k = 0) and get
        // the exact tangent.
        let newton = (c_m != 0.0 || at_rest) && c_k != 0.0;
        let mut ke = ElementMatrix::zeros();
        let mut e_index = 0;
        for b in &self.bodies {
            let n = b.n_elements();
            let mut el = 0;
            // A time step's matrix: elements sharing a kernel four at a time (the lanes give
            // every element the operations it gets alone).
            while newton && !at_rest && b.twisted.is_empty() && el + ELEMENT_LANES <= n {
                self.add_element_matrices::<ELEMENT_LANES>(b, el, e_index, q, (c_m, c_k), &mut ke, k);
                el += ELEMENT_LANES;
                e_index += ELEMENT_LANES;
            }
            for el in el..n {
                let first = b.offset + NODE_DOF * el;
                // c_m M_e on the upper triangle (what the scatter reads; M_e is zero off its diagonal inside a 3×3 block)
                ke.as_mut_slice().fill(0.0); // a memset (nalgebra's `fill` walks the matrix entry by entry)
                for &(a, bb, m) in b.element.mass_nz.iter().filter(|(a, bb, _)| a <= bb) {
                    for i in 0..3 {
                        ke[(3 * a + i, 3 * bb + i)] = c_m * m;
                    }
                }
                let e = &q[first..first + ELEMENT_DOF];
                if at_rest && c_k != 0.0 {
                    b.kernel(el).add_rest_tangent_upper(e, c_k, &mut ke);
                } else if newton {
                    b.kernel(el).add_newton_tangent_upper(e, c_k, &mut ke);
                } else if c_k != 0.0 {
                    b.kernel(el).add_elastic_tangent_upper(e, c_k, &mut ke);
                }
                self.scatter_element(first, e_index, &mut ke, k);
                e_index += 1;
            }
        }
        if c_k != 0.0 {
            let lf = self.load_factor;
            for (st, m) in &self.moments {
                moment_tangent(*st, m, q, c_k * lf, |i, j, blk| self.scatter_block(i, j, blk, k));
            }
            for th in &self.thrusts {
                th.tangent(lf * th.magnitude(t), q, c_k, |i, j, blk| self.scatter_block(i, j, blk, k));
            }
        }
        for p in &self.point_inertia {
            ke.as_mut_slice().fill(0.0);
            for &(a, bb, m) in p.mass_nz.iter().filter(|(a, bb, _)| a <= bb) {
                for i in 0..3 {
                    ke[(3 * a + i, 3 * bb + i)] = c_m * m;
                }
            }
            self.scatter_element(p.first, p.e_index, &mut ke, k);
        }
        if c_k != 0.0 {
            for tie in &self.ties {
                self.scatter_tie(tie.first, &tie.tangent(q, c_k, newton), k);
            }
        }
        for spring in &self.springs {
            let kin = spring.kinematics(q, true);
            let t = spring.tangent(&kin, v, c_c, c_k, newton && !at_rest);
            self.scatter_spring(&kin, &t, k);
        }
    }

    /// Add a node tie's 9×9 matrix (the node's `r_x`, `r_y`, `r_z` from `first`) through the
    /// chosen form.
    fn scatter_tie(&self, first: usize, t: &TieMatrix, k: &mut MatView<'_>) {
        if let SolvePath::Dae = self.options.path {
            // The tie's matrix is symmetric (its lower triangle is a copy of the upper): one
            // block, given by its upper triangle, instead of 81 single entries.
            k.add_symmetric_upper(first, t);
            return;
        }
        for b in 0..9 {
            for a in 0..9 {
                let x = t[(a, b)];
                for &(za, ca) in self.reduction.row(first + a) {
                    for &(zb, cb) in self.reduction.row(first + b) {
                        k.add(za, zb, ca * cb * x);
                    }
                }
            }
        }
    }

    /// Add a spring's local matrix (coordinates `kin.idx`, not necessarily symmetric) through
    /// the chosen form.
    fn scatter_spring(&self, kin: &Kinematics, t: &Hessian, k: &mut MatView<'_>) {
        for b in 0..kin.n {
            for a in 0..kin.n {
                let x = t[(a, b)];
                match self.options.path {
                    SolvePath::Dae => k.add(kin.idx[a], kin.idx[b], x),
                    SolvePath::Ode => {
                        for &(za, ca) in self.reduction.row(kin.idx[a]) {
                            for &(zb, cb) in self.reduction.row(kin.idx[b]) {
                                k.add(za, zb, ca * cb * x);
                            }
                        }
                    }
                }
            }
        }
    }

    /// Add a symmetric element matrix, given by its upper triangle (the lower one is overwritten
    /// when the ODE reduction needs the whole matrix).
    fn scatter_element(&self, first: usize, e_index: usize, ke: &mut ElementMatrix, k: &mut MatView<'_>) {
        match (self.options.path, self.element_z[e_index], &self.element_reduced[e_index]) {
            (SolvePath::Dae, _, _) => k.add_symmetric_upper(first, ke),
            (SolvePath::Ode, Some(z), _) => k.add_symmetric_upper(z, ke),
            (SolvePath::Ode, None, Some(red)) => {
                mirror_upper_inplace(ke);
                let nz = red.z.len();
                let mut buffer = scratch(&self.reduced_block);
                let block = &mut buffer[..nz * nz];
                block.fill(0.0);
                for (bb, rb) in red.rows.iter().enumerate() {
                    for (a, ra) in red.rows.iter().enumerate() {
                        let x = ke[(a, bb)];
                        if x == 0.0 {
                            continue;
                        }
                        for &(pb, cb) in rb {
                            for &(pa, ca) in ra {
                                block[pb * nz + pa] += ca * cb * x;
                            }
                        }
                    }
                }
                k.add_symmetric_indexed(&red.z, block);
            }
            (SolvePath::Ode, None, None) => unreachable!("every element off the contiguous map has a reduction"),
        }
    }

    /// `c_m M_e + c_k K_e` (Newton's tangent of a time step, upper triangle) of the `L`
    /// elements from `el0` of body `b`, computed together, then scattered one after the other
    /// through `ke` as [`add_iteration_matrix`](Self::add_iteration_matrix) scatters single
    /// elements.
    #[allow(clippy::too_many_arguments)] // the body's run of elements, the state, the weights, the targets
    fn add_element_matrices<const L: usize>(
        &self,
        b: &Body,
        el0: usize,
        e_index0: usize,
        q: &[f64],
        (c_m, c_k): (f64, f64),
        ke: &mut ElementMatrix,
        k: &mut MatView<'_>,
    ) {
        let first = |l: usize| b.offset + NODE_DOF * (el0 + l);
        let mut lanes: LaneMatrix<L> = [[[0.0; L]; ELEMENT_DOF]; ELEMENT_DOF];
        for &(a, bb, m) in b.element.mass_nz.iter().filter(|(a, bb, _)| a <= bb) {
            for i in 0..3 {
                lanes[3 * bb + i][3 * a + i] = [c_m * m; L];
            }
        }
        let e: [&[f64]; L] = std::array::from_fn(|l| &q[first(l)..first(l) + ELEMENT_DOF]);
        b.kernel(el0).add_newton_tangent_upper_lanes(e, c_k, &mut lanes);
        for l in 0..L {
            // the upper triangle: the scatter reads no more (the lower one stays zero)
            for (j, (col, lane_col)) in ke.data.0.iter_mut().zip(&lanes).enumerate() {
                for (x, y) in col[..=j].iter_mut().zip(lane_col) {
                    *x = y[l];
                }
            }
            self.scatter_element(first(l), e_index0 + l, ke, k);
        }
    }

    fn scatter_block(&self, i0: usize, j0: usize, blk: &Matrix3<f64>, k: &mut MatView<'_>) {
        match self.options.path {
            SolvePath::Dae => k.add_block(i0, j0, blk),
            SolvePath::Ode => {
                for a in 0..3 {
                    for bb in 0..3 {
                        for &(za, ca) in self.reduction.row(i0 + a) {
                            for &(zb, cb) in self.reduction.row(j0 + bb) {
                                k.add(za, zb, ca * cb * blk[(a, bb)]);
                            }
                        }
                    }
                }
            }
        }
    }

    /// Assemble `c_m M + c_k K_t` on full coordinates into a dense column-major matrix
    /// (DAE layout regardless of the path; used by the static solver and the modal analysis).
    /// The hinge springs enter with their stiffness at rest (`θ̇ = 0`, no damping).
    pub(crate) fn assemble_full_inplace(&self, t: f64, q: &[f64], c_m: f64, c_k: f64, k: &mut MatView<'_>) {
        let mut ke = ElementMatrix::zeros();
        for b in &self.bodies {
            for el in 0..b.n_elements() {
                let first = b.offset + NODE_DOF * el;
                ke.as_mut_slice().fill(0.0);
                for &(a, bb, m) in &b.element.mass_nz {
                    for i in 0..3 {
                        ke[(3 * a + i, 3 * bb + i)] += c_m * m;
                    }
                }
                b.kernel(el).add_elastic_tangent(&q[first..first + ELEMENT_DOF], c_k, &mut ke);
                k.add_block(first, first, &ke);
            }
        }
        let lf = self.load_factor;
        for (st, m) in &self.moments {
            moment_tangent(*st, m, q, c_k * lf, |i, j, blk| k.add_block(i, j, blk));
        }
        for th in &self.thrusts {
            th.tangent(lf * th.magnitude(t), q, c_k, |i, j, blk| k.add_block(i, j, blk));
        }
        for p in &self.point_inertia {
            ke.as_mut_slice().fill(0.0);
            for &(a, bb, m) in &p.mass_nz {
                for i in 0..3 {
                    ke[(3 * a + i, 3 * bb + i)] += c_m * m;
                }
            }
            k.add_block(p.first, p.first, &ke);
        }
        for tie in &self.ties {
            let t = tie.tangent(q, c_k, false);
            for b in 0..9 {
                for a in 0..9 {
                    k.add(tie.first + a, tie.first + b, t[(a, b)]);
                }
            }
        }
        for spring in &self.springs {
            let kin = spring.kinematics(q, true);
            let t = spring.tangent(&kin, None, 0.0, c_k, false);
            for b in 0..kin.n {
                for a in 0..kin.n {
                    k.add(kin.idx[a], kin.idx[b], t[(a, b)]);
                }
            }
        }
    }

    /// Elastic energy split by strain kind (J, indexed by `StrainKind as usize`): shows how much
    /// sits in the cross-section penalties and the shear.
    pub fn elastic_energy_by_kind(&self, q: &[f64]) -> [f64; crate::strain::N_STRAINS] {
        self.with_full(q, |q| self.elastic_energy_by_kind_full(q))
    }

    fn elastic_energy_by_kind_full(&self, q: &[f64]) -> [f64; crate::strain::N_STRAINS] {
        let mut u = [0.0; crate::strain::N_STRAINS];
        for b in &self.bodies {
            for k in 0..b.n_elements() {
                let first = b.offset + NODE_DOF * k;
                for (x, y) in u.iter_mut().zip(b.kernel(k).elastic_energy_by_kind(&q[first..first + ELEMENT_DOF])) {
                    *x += y;
                }
            }
        }
        u
    }
}

/// Elements whose elastic forces are evaluated together (see [`Element::elastic_forces`]).
const ELEMENT_LANES: usize = 4;

/// `r += M_e v̇ + f_el(q)` of the elements `k0..k0 + L` of body `b`, added element by element.
fn add_element_residuals<const L: usize>(b: &Body, k0: usize, q: &[f64], v_dot: &[f64], r: &mut [f64]) {
    let first = |l: usize| b.offset + NODE_DOF * (k0 + l);
    let e: [&[f64]; L] = std::array::from_fn(|l| &q[first(l)..first(l) + ELEMENT_DOF]);
    let mut f = [[0.0; ELEMENT_DOF]; L];
    b.kernel(k0).elastic_forces(e, &mut f);
    for (l, fl) in f.iter().enumerate() {
        let range = first(l)..first(l) + ELEMENT_DOF;
        let out = &mut r[range.clone()];
        b.element.add_mass_times(1.0, &v_dot[range], out);
        for (o, x) in out.iter_mut().zip(fl) {
            *o += x;
        }
    }
}

impl ConstrainedSystem for Model {
    fn n_coords(&self) -> usize {
        self.n_dof()
    }
    fn n_dof(&self) -> usize {
        match self.options.path {
            SolvePath::Dae => self.n_full,
            SolvePath::Ode => self.reduction.n_reduced(),
        }
    }
    fn n_holonomic(&self) -> usize {
        match self.options.path {
            SolvePath::Dae => self.rows.len(),
            SolvePath::Ode => 0,
        }
    }

    fn residual_inplace(&self, t: f64, q: &[f64], v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        match self.options.path {
            SolvePath::Dae => self.full_residual_at(t, q, Some(v), v_dot, r),
            SolvePath::Ode => {
                let mut w = scratch(&self.work);
                let Workspace { q: qf, v: af, r: rf, rate } = &mut *w;
                self.reduction.expand_inplace(q, qf);
                self.reduction.expand_rate_inplace(v_dot, af);
                let vf = if self.damped {
                    self.reduction.expand_rate_inplace(v, rate);
                    Some(&rate[..])
                } else {
                    None
                };
                self.full_residual_at(t, qf, vf, af, rf);
                self.reduction.project_inplace(rf, r);
            }
        }
    }

    fn iteration_matrix_inplace(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        _v_dot: &[f64],
        c_m: f64,
        c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        match self.options.path {
            SolvePath::Dae => self.add_iteration_matrix(t, q, Some(v), c_m, c_c, c_k, false, k),
            SolvePath::Ode => {
                let mut w = scratch(&self.work);
                let Workspace { q: qf, rate, .. } = &mut *w;
                self.reduction.expand_inplace(q, qf);
                let vf = if self.damped {
                    self.reduction.expand_rate_inplace(v, rate);
                    Some(&rate[..])
                } else {
                    None
                };
                self.add_iteration_matrix(t, qf, vf, c_m, c_c, c_k, false, k);
            }
        }
    }

    /// The residual at rest and Newton's matrix at rest (docs/ancf.md §9): the exact tangent
    /// without the geometric terms of the near-rigid strains.
    fn residual_and_static_matrix_inplace(&self, t: f64, q: &[f64], zeros: &[f64], r: &mut [f64], k: &mut MatView<'_>) {
        self.residual_inplace(t, q, zeros, zeros, r);
        match self.options.path {
            SolvePath::Dae => self.add_iteration_matrix(t, q, None, 0.0, 0.0, 1.0, true, k),
            SolvePath::Ode => {
                let mut w = scratch(&self.work);
                let Workspace { q: qf, .. } = &mut *w;
                self.reduction.expand_inplace(q, qf);
                self.add_iteration_matrix(t, qf, None, 0.0, 0.0, 1.0, true, k);
            }
        }
    }

    fn has_static_matrix(&self) -> bool {
        true
    }

    /// The nodes turned rather than pushed (docs/ancf.md §9); the ODE path's independent
    /// coordinates keep the linear step.
    fn adjust_static_step(&self, q: &[f64], dq: &mut [f64]) {
        if self.options.path == SolvePath::Dae {
            self.turn_node_steps(q, dq);
        }
    }

    fn phi_inplace(&self, _t: f64, q: &[f64], phi: &mut [f64]) {
        if self.options.path == SolvePath::Dae {
            for (p, row) in phi.iter_mut().zip(&self.rows) {
                *p = row.value(q);
            }
        }
    }

    fn phi_q_inplace(&self, _t: f64, _q: &[f64], j: &mut MatView<'_>) {
        if self.options.path == SolvePath::Dae {
            for (i, row) in self.rows.iter().enumerate() {
                for &(col, c) in &row.entries {
                    j.add(i, col, c);
                }
            }
        }
    }

    fn phi_q_is_constant(&self) -> bool {
        true
    }

    /// The springs' unwrapping reference: the angles of the accepted step (docs/ancf.md §11).
    fn post_step(&mut self, _t: f64, q: &mut [f64], _v: &mut [f64], _v_dot: &mut [f64], _a: &mut [f64]) {
        if !self.springs.is_empty() {
            self.accept_hinge_angles(q);
        }
    }

    /// DAE: one band block per body (node-ordered coordinates, half-bandwidth 23), the joint
    /// rows on the border; bodies coupled by a flared hinge's spring share a block (the spring
    /// couples the parent's last node to the child's first). ODE: one band block over all
    /// independent coordinates with the half-bandwidth of the eliminated couplings.
    fn matrix_structure(&self) -> Option<genalpha::BandedBorder> {
        let blocks = match self.options.path {
            SolvePath::Dae => {
                let bodies = self.bodies.iter().map(|b| (b.offset, NODE_DOF * b.n_nodes, ELEMENT_DOF - 1)).collect();
                if self.springs.iter().any(HingeSpring::couples_bodies) { self.merged_blocks(bodies) } else { bodies }
            }
            SolvePath::Ode => {
                let adj = self.adjacency();
                let w =
                    adj.iter().enumerate().flat_map(|(i, l)| l.iter().map(move |&j| i.abs_diff(j))).max().unwrap_or(0);
                vec![(0, self.reduction.n_reduced(), w)]
            }
        };
        Some(genalpha::BandedBorder { blocks, node_bandwidth: None })
    }

    fn increment_weight(&self, i: usize) -> f64 {
        match self.options.path {
            SolvePath::Dae => self.weights[i],
            SolvePath::Ode => self.weights[self.reduction.full_of(i)],
        }
    }

    /// DAE: one rotation per node, the rotation part of `F F_ref⁻¹` with `F = [r_x r_y r_z]`
    /// (docs/ancf.md §8). ODE: none (the reduced coordinates mix nodes' frames).
    fn corotation_inplace(&self, q_ref: &[f64], q: &[f64], rotations: &mut Vec<f64>) -> bool {
        if self.options.path != SolvePath::Dae {
            return false;
        }
        rotations.clear();
        for b in &self.bodies {
            for k in 0..b.n_nodes {
                let o = b.offset + NODE_DOF * k;
                let turn = crate::frame::node_turn(&q_ref[o + 3..o + 12], &q[o + 3..o + 12]);
                rotations.extend_from_slice(turn.as_slice());
            }
        }
        true
    }

    /// The node's four vectors `r, r_x, r_y, r_z` turned by the node's rotation.
    fn corotate_inplace(&self, rotations: &[f64], x: &mut [f64], transpose: bool) {
        let mut turns = rotations.chunks_exact(9);
        for b in &self.bodies {
            for k in 0..b.n_nodes {
                let Some(r) = turns.next() else { return };
                let r = Matrix3::from_column_slice(r);
                let o = b.offset + NODE_DOF * k;
                for v in x[o..o + NODE_DOF].chunks_exact_mut(3) {
                    let y = Vector3::new(v[0], v[1], v[2]);
                    let z = if transpose { r.tr_mul(&y) } else { r * y };
                    v.copy_from_slice(z.as_slice());
                }
            }
        }
    }
}

impl Model {
    /// `static_step::turn_node_steps` on every body's nodes (full coordinates), the step first
    /// shortened to turn no node by more than `static_step::MAX_TURN`.
    pub(crate) fn turn_node_steps(&self, q: &[f64], dq: &mut [f64]) {
        use crate::static_step::{MAX_TURN, largest_turn};
        let turn = self.bodies.iter().map(|b| largest_turn(b.offset, b.n_nodes, q, dq)).fold(0.0, f64::max);
        if turn > MAX_TURN {
            dq.iter_mut().for_each(|d| *d *= MAX_TURN / turn);
        }
        for b in &self.bodies {
            crate::static_step::turn_node_steps(b.offset, b.n_nodes, q, dq);
        }
    }

    /// The DAE band blocks `(first, len, half-bandwidth)` with the bodies a flared hinge's spring
    /// couples merged into one block (with everything between them), whose half-bandwidth covers
    /// the spring's couplings.
    fn merged_blocks(&self, bodies: Vec<(usize, usize, usize)>) -> Vec<(usize, usize, usize)> {
        let mut spans: Vec<(usize, usize, usize)> = bodies.iter().map(|&(f, n, w)| (f, f + n, w)).collect();
        for s in self.springs.iter().filter(|s| s.couples_bodies()) {
            let (idx, n) = s.coordinates();
            let (lo, hi) = (idx[..n].iter().min().copied(), idx[..n].iter().max().copied());
            if let (Some(lo), Some(hi)) = (lo, hi) {
                spans.push((lo, hi + 1, hi - lo));
            }
        }
        spans.sort_unstable();
        let mut merged: Vec<(usize, usize, usize)> = Vec::new();
        for (start, end, w) in spans {
            match merged.last_mut() {
                Some(last) if start < last.1 => {
                    last.1 = last.1.max(end);
                    last.2 = last.2.max(w);
                }
                _ => merged.push((start, end, w)),
            }
        }
        merged.into_iter().map(|(start, end, w)| (start, end - start, w)).collect()
    }
}

impl Model {
    /// Number of force elements (hinge springs and dampers, thrusts) in the model.
    pub fn n_force_elements(&self) -> usize {
        self.springs.len() + self.thrusts.len()
    }

    /// Whether the model has thrusts (the `thrust_work` column).
    pub fn has_thrust(&self) -> bool {
        !self.thrusts.is_empty()
    }

    /// The power of the thrusts `Σ F · ṙ(s)` at time `t`, coordinates `q` and velocities `v`
    /// (the model's form), W. Does not allocate.
    pub fn thrust_power(&self, t: f64, q: &[f64], v: &[f64]) -> f64 {
        if self.thrusts.is_empty() {
            return 0.0;
        }
        let mut sens = scratch(&self.sensor);
        let (qf, vf, _) = &mut *sens;
        let (qf, vf) = (&mut qf[..self.n_full], &mut vf[..self.n_full]);
        self.full_coordinates_inplace(q, qf);
        self.full_velocities_inplace(v, vf);
        let lf = self.load_factor;
        self.thrusts.iter().map(|th| th.power(lf * th.magnitude(t), qf, vf)).sum()
    }
}

/// The scene's force elements built on the model's joints, bodies and full reference
/// coordinates: the hinge springs and the thrusts.
fn force_elements(
    forces: &[ForceElement],
    joints: &[Joint],
    bodies: &[Body],
    q_ref: &[f64],
) -> (Vec<HingeSpring>, Vec<Thrust>) {
    let (mut springs, mut thrusts) = (Vec::new(), Vec::new());
    for f in forces {
        match *f {
            ForceElement::HingeSpring { joint, stiffness, damping, rest } => {
                springs.push(HingeSpring::new(joint, &joints[joint], bodies, stiffness, damping, rest));
            }
            ForceElement::Thrust { body, at, ref direction, ref magnitude } => {
                thrusts.push(Thrust::new(&bodies[body], at, direction, magnitude.clone(), q_ref));
            }
        }
    }
    (springs, thrusts)
}

/// The section ties of the hinges (docs/ancf.md §3.5): at each node a hinge acts on, the
/// section's metric strains `½(|r_y|²−1), ½(|r_z|²−1), r_y·r_z`, and where the hinge's axis
/// equation involves `r_x` also `½(|r_x|²−1), r_x·r_y, r_x·r_z`, with the stiffness `c_t EI / l`
/// of the rotation each one resists: `r_x·r_y` EI_zz, `r_x·r_z` EI_yy, `r_y·r_z` GJ, and each
/// stretch the larger of its vector's two (a stretch is loaded by moments about both), at most
/// [`TIE_CAP`] `max(EA, GA) l`. Clamps hold their section's slopes exactly and need none.
/// Upper bound of a section tie's stiffness in units of the slopes' stiffest node-local term
/// `max(EA, GA) l` (docs/ancf.md §3.5): stiffer ties on very stiff, thick sections shrink
/// Newton's convergence radius.
const TIE_CAP: f64 = 50.0;

fn joint_ties(joints: &[Joint], bodies: &[Body], factor: f64) -> Vec<NodeTie> {
    // whether an axis `Σ α_b r_b` involves r_x (round-off of a rotated frame is not)
    let on_x = |alpha: &Vector3<f64>| alpha[0].abs() > 1e-9 * alpha.norm();
    let mut ties: Vec<NodeTie> = Vec::new();
    if factor == 0.0 {
        return ties;
    }
    let mut tie = |body: usize, node: usize, with_x: bool| {
        let b = &bodies[body];
        let first = b.offset + NODE_DOF * node + 3;
        let (s, l) = (&b.spec.section, b.element.l);
        // c_t EI/l, at most TIE_CAP times the slopes' own stiffest node-local term (EA l)
        let k = |ei: f64| (factor * ei / l).min(TIE_CAP * s.ea.max(s.ga_y).max(s.ga_z) * l);
        let x = if with_x { 1.0 } else { 0.0 };
        // order of NodeTie::k: xx, yy, zz, xy, xz, yz
        let new = [
            x * k(s.ei_yy.max(s.ei_zz)),
            k(s.gj.max(s.ei_zz)),
            k(s.gj.max(s.ei_yy)),
            x * k(s.ei_zz),
            x * k(s.ei_yy),
            k(s.gj),
        ];
        match ties.iter_mut().find(|t| t.first == first) {
            Some(t) => t.k.iter_mut().zip(new).for_each(|(a, b)| *a = a.max(b)),
            None => ties.push(NodeTie { first, k: new }),
        }
    };
    for j in joints {
        match j {
            Joint::Ground { body, alpha, .. } => tie(*body, 0, on_x(alpha)),
            Joint::Flared { parent, child, alpha_p, alpha_c, lock, .. } => {
                let free = lock.is_none();
                tie(*parent, bodies[*parent].n_nodes - 1, free && on_x(alpha_p));
                tie(*child, 0, free && on_x(alpha_c));
            }
            Joint::Clamp { .. } | Joint::Free => {}
        }
    }
    ties
}

/// Lock a model's scratch buffer. The model's methods take `&self` (the integrator's trait), so
/// their per-call buffers sit behind a `Mutex`: the model stays `Send + Sync`, and a call never
/// nests a second lock of the same buffer. A poisoned lock only means a panic elsewhere left the
/// buffer half written; every user overwrites it first.
fn scratch<T>(buffer: &Mutex<T>) -> MutexGuard<'_, T> {
    buffer.lock().unwrap_or_else(PoisonError::into_inner)
}
