//! The multibody GEBF model: bodies with floating frames, joints, gravity, nodal loads; the
//! [`genalpha::ConstrainedSystem`] implementation and the sensors of the harness API.

use crate::Energies;
use crate::body::Body;
use crate::clamp::Clamp;
use crate::crv::{M3, V3, rotation_matrix};
use crate::element::{ElementState, Mat24, V_OFF, Vec24};
use crate::flared_hinge::FlaredHinge;
use crate::ground_hinge::GroundHinge;
use crate::hinge_spring::{HingeSpring, principal_angle, unwrap};
use crate::inertia::MatrixCoefficients;
use crate::joint::Joint;
use crate::loads::{NodalLoad, add_load, add_load_tangent};
use crate::quaternion::Quaternion;
use crate::rigid_slice::{add_element_gravity, add_element_inertia, element_potential};
use crate::stiffness::add_elastic;
use crate::thrust::Thrust;
use crate::{BodySpec, Error, ForceElement, JointSpec, Options, Scene};
use genalpha::{ConstrainedSystem, MatView, State};
use nalgebra::Vector3;

/// The GEBF multibody model. Implements [`genalpha::ConstrainedSystem`].
#[derive(Debug, Clone)]
pub struct Model {
    pub(crate) bodies: Vec<Body>,
    pub(crate) joints: Vec<Joint>,
    /// First velocity-constraint row of each joint.
    joint_row: Vec<usize>,
    /// Joint indices, parents before children (for the projection).
    projection_order: Vec<usize>,
    pub(crate) gravity: V3,
    options: Options,
    n_dof: usize,
    n_coords: usize,
    n_rows: usize,
    /// Nodal loads per body and node.
    pub(crate) loads: Vec<Vec<NodalLoad>>,
    n_loaded: usize,
    /// Factor on gravity and nodal loads (load stepping in statics).
    pub(crate) load_scale: f64,
    /// Hinge springs and dampers.
    springs: Vec<HingeSpring>,
    /// Thrusts, follower forces (docs/gebf.md §16).
    thrusts: Vec<Thrust>,
    /// Per joint: the hinge angle θ of the last accepted step (free hinges; 0 otherwise), rad,
    /// against which the principal angle is unwrapped (docs/gebf.md §13).
    hinge_last: Vec<f64>,
    /// The momentum projection's last accepted state (with `options.conserve_momentum`).
    pub(crate) momentum_hold: Option<crate::momentum_hold::MomentumHold>,
}

/// The element's local unknowns as two contiguous global ranges: (first local index, first
/// global index, length) for its nodes (node 0 is skipped) and for the frame.
fn local_ranges(b: &Body, e: usize) -> [(usize, usize, usize); 2] {
    let nodes = if e == 0 {
        (6, b.node_dof(1).expect("node 1 exists"), 12)
    } else {
        (0, b.node_dof(2 * e).expect("e ≥ 1"), 18)
    };
    [nodes, (V_OFF, b.frame_dof(), 6)]
}

/// Add an element matrix into the global view (column by column, contiguous row ranges).
fn scatter_matrix(b: &Body, e: usize, mat: &Mat24, k: &mut MatView<'_>) {
    let ranges = local_ranges(b, e);
    let data = mat.as_slice();
    for &(lc, gc, nc) in &ranges {
        for &(lr, gr, nr) in &ranges {
            k.add_submatrix(gr, gc, nr, nc, &data[24 * lc + lr..], 24, 1.0);
        }
    }
}

fn check_body(field: String, b: usize, n_bodies: usize) -> Result<(), Error> {
    if b >= n_bodies { Err(Error::NoSuchBody { field, body: b, n_bodies }) } else { Ok(()) }
}

impl Model {
    /// Validates everything and returns an [`Error`] naming the field. A scene without force
    /// elements; see [`from_scene`](Self::from_scene).
    pub fn new(
        bodies: &[BodySpec],
        joints: &[JointSpec],
        gravity: Vector3<f64>,
        options: Options,
    ) -> Result<Model, Error> {
        Self::from_scene(&Scene::new(bodies.to_vec(), joints.to_vec(), gravity), options)
    }

    /// Validates the scene (see [`Scene::validate`]) and the options, and builds the model.
    pub fn from_scene(scene: &Scene, options: Options) -> Result<Model, Error> {
        scene.validate()?;
        options.validate()?;
        let (bodies, joints, gravity) = (&scene.bodies[..], &scene.joints[..], scene.gravity);
        let (mut dof, mut coord) = (0, 0);
        let mut bs = Vec::with_capacity(bodies.len());
        for spec in bodies {
            let b = Body::new(spec, dof, coord);
            dof += b.n_dof();
            coord += b.n_coords();
            bs.push(b);
        }
        let nb = bodies.len();
        // Each body's parent, for the projection order (the scene has no loops: validated).
        let mut parent: Vec<Option<usize>> = vec![None; nb];
        let js: Vec<Joint> = joints
            .iter()
            .map(|spec| match *spec {
                JointSpec::GroundHinge { body, ref axis } => Joint::Ground(GroundHinge::new(body, axis, &bs[body])),
                JointSpec::Clamp { body } => Joint::Clamp(Clamp { body }),
                JointSpec::Free { .. } => Joint::Free,
                JointSpec::FlaredHinge { parent: p, child: c, beta }
                | JointSpec::LockedHinge { parent: p, child: c, beta, .. } => {
                    parent[c] = Some(p);
                    let locked = match *spec {
                        JointSpec::LockedHinge { fold, .. } => Some(fold),
                        _ => None,
                    };
                    Joint::Flared(FlaredHinge::new(p, c, beta, locked, &bs[p], &bs[c]))
                }
            })
            .collect();
        // Depth of every body along its parents.
        let depth: Vec<usize> = (0..nb).map(|b| std::iter::successors(parent[b], |&p| parent[p]).count()).collect();
        let joint_body: Vec<usize> = joints
            .iter()
            .map(|s| match s {
                JointSpec::GroundHinge { body, .. } | JointSpec::Clamp { body } | JointSpec::Free { body } => *body,
                JointSpec::FlaredHinge { child, .. } | JointSpec::LockedHinge { child, .. } => *child,
            })
            .collect();
        let mut projection_order: Vec<usize> = (0..js.len()).collect();
        projection_order.sort_by_key(|&j| depth[joint_body[j]]);
        let mut joint_row = Vec::with_capacity(js.len());
        let mut rows = 0;
        for j in &js {
            joint_row.push(rows);
            rows += j.n_rows();
        }
        let loads = bs.iter().map(|b| vec![NodalLoad::default(); b.n_nodes()]).collect();
        let mut springs = Vec::new();
        let mut thrusts = Vec::new();
        for f in &scene.forces {
            match *f {
                ForceElement::HingeSpring { joint, stiffness, damping, rest } => {
                    springs.push(HingeSpring { joint, stiffness, damping, rest });
                }
                ForceElement::Thrust { body, at, ref direction, ref magnitude } => {
                    let frame_at = bodies[body].section_frame(at);
                    thrusts.push(Thrust::new(body, &bs[body], at, &frame_at, direction, magnitude.clone()));
                }
            }
        }
        let hinge_last = vec![0.0; js.len()];
        Ok(Model {
            bodies: bs,
            joints: js,
            joint_row,
            projection_order,
            gravity,
            options,
            n_dof: dof,
            n_coords: coord,
            n_rows: rows,
            loads,
            n_loaded: 0,
            load_scale: 1.0,
            springs,
            thrusts,
            hinge_last,
            momentum_hold: None,
        })
    }

    /// The options in use.
    pub fn options(&self) -> &Options {
        &self.options
    }

    /// Switch the position-level stabilisation on or off.
    pub fn set_stabilization(&mut self, on: bool) {
        self.options.stabilization = on;
    }

    /// The undeformed reference configuration at rest, sized for genalpha (q, zero v, ...).
    pub fn initial_state(&self) -> State {
        State::at_rest(self, 0.0, self.reference_coordinates())
    }

    /// The storage vector `q` of the reference configuration.
    pub fn reference_coordinates(&self) -> Vec<f64> {
        let mut q = vec![0.0; self.n_coords];
        for b in &self.bodies {
            for i in 1..b.n_nodes() {
                let k = b.node_coord(i).expect("i ≥ 1");
                q[k..k + 3].copy_from_slice(b.node_ref(i).as_slice());
                if let Some(psi0) = b.node_psi0(i) {
                    q[k + 3..k + 6].copy_from_slice(psi0.as_slice());
                }
            }
            let f = b.frame_coord();
            q[f..f + 3].copy_from_slice(b.start.as_slice());
            b.quat0.write_to(&mut q[f + 3..f + 7]);
        }
        q
    }

    /// Number of bodies.
    pub fn n_bodies(&self) -> usize {
        self.bodies.len()
    }

    /// Number of nodes of body `body` (including its node 0 at the frame origin).
    ///
    /// # Panics
    /// When `body` is out of range.
    pub fn n_nodes(&self, body: usize) -> usize {
        self.bodies[body].n_nodes()
    }

    /// Total length of all bodies (m).
    pub fn span(&self) -> f64 {
        self.bodies.iter().map(|b| b.length).sum()
    }

    /// Arc length of node `node` of `body` from the body's start in the reference, m.
    pub fn node_arc_length(&self, body: usize, node: usize) -> Result<f64, Error> {
        self.check_node(body, node)?;
        Ok(self.bodies[body].node_ref(node).x)
    }

    fn check_node(&self, body: usize, node: usize) -> Result<(), Error> {
        let nb = self.bodies.len();
        check_body("body".into(), body, nb)?;
        let n_nodes = self.bodies[body].n_nodes();
        if node >= n_nodes {
            return Err(Error::NoSuchNode { body, node, n_nodes });
        }
        Ok(())
    }

    /// Frame origin `r_A` (global, m) and orientation `C^{GA}` of body `body`.
    ///
    /// # Panics
    /// When `body` is out of range or `q` is too short.
    pub fn body_frame(&self, q: &[f64], body: usize) -> (Vector3<f64>, M3) {
        let (r, chi) = self.bodies[body].frame_state(q);
        (r, chi.to_rotation_matrix())
    }

    /// Global position of a node, m.
    pub fn node_position(&self, q: &[f64], body: usize, node: usize) -> Result<Vector3<f64>, Error> {
        self.check_node(body, node)?;
        let b = &self.bodies[body];
        let (r, chi) = b.frame_state(q);
        let (ri, _) = b.node_state(q, node);
        Ok(r + chi.rotate(&ri))
    }

    /// Section frame of a node, `C^{GB}`: columns = section x (beam axis), y, z in global
    /// components.
    pub fn node_frame(&self, q: &[f64], body: usize, node: usize) -> Result<M3, Error> {
        self.check_node(body, node)?;
        let b = &self.bodies[body];
        let (_, chi) = b.frame_state(q);
        let (_, psi) = b.node_state(q, node);
        Ok(chi.to_rotation_matrix() * rotation_matrix(&psi))
    }

    /// Global velocity of a node, m/s: `C^{GA}(v_A + R_dot + omega_A × R)`.
    pub fn node_velocity(&self, q: &[f64], v: &[f64], body: usize, node: usize) -> Result<Vector3<f64>, Error> {
        self.check_node(body, node)?;
        let b = &self.bodies[body];
        let (_, chi) = b.frame_state(q);
        let (ri, _) = b.node_state(q, node);
        let (rd, _) = b.node_rates(v, node);
        let (va, wa) = b.frame_rates(v);
        Ok(chi.rotate(&(va + rd + wa.cross(&ri))))
    }

    /// Global angular velocity of a node's section, rad/s: `C^{GB}(T psi_dot + C^{BA} omega_A)`.
    pub fn node_angular_velocity(&self, q: &[f64], v: &[f64], body: usize, node: usize) -> Result<Vector3<f64>, Error> {
        self.check_node(body, node)?;
        let b = &self.bodies[body];
        let (_, chi) = b.frame_state(q);
        let (_, psi) = b.node_state(q, node);
        let (_, psid) = b.node_rates(v, node);
        let (_, wa) = b.frame_rates(v);
        let c = rotation_matrix(&psi);
        Ok(chi.rotate(&(c * (crate::crv::tangent(&psi) * psid) + wa)))
    }

    /// Apply (replace) a nodal load: force and moment in global components, held fixed until
    /// changed. This is the hook for the aerodynamic coupling: set the loads of the current
    /// step before calling `GenAlpha::step`. The power of the loads is
    /// `Σ F·node_velocity + M·node_angular_velocity`.
    pub fn set_nodal_load(&mut self, body: usize, node: usize, load: NodalLoad) -> Result<(), Error> {
        self.check_node(body, node)?;
        for (k, x) in load.force.iter().chain(load.moment.iter()).enumerate() {
            if !x.is_finite() {
                return Err(Error::NonFinite { field: format!("load[{k}]"), value: *x });
            }
        }
        self.loads[body][node] = load;
        self.n_loaded = self.loads.iter().flatten().filter(|l| !l.is_zero()).count();
        Ok(())
    }

    /// The load currently applied at a node.
    pub fn nodal_load(&self, body: usize, node: usize) -> Result<NodalLoad, Error> {
        self.check_node(body, node)?;
        Ok(self.loads[body][node])
    }

    /// Remove all nodal loads.
    pub fn clear_nodal_loads(&mut self) {
        self.loads.iter_mut().flatten().for_each(|l| *l = NodalLoad::default());
        self.n_loaded = 0;
    }

    /// Centroid of the free end section of the last body (global, m).
    pub fn tip_position(&self, q: &[f64]) -> Vector3<f64> {
        let b = self.bodies.len() - 1;
        let n = self.bodies[b].n_nodes() - 1;
        let body = &self.bodies[b];
        let (r, chi) = body.frame_state(q);
        let (ri, _) = body.node_state(q, n);
        r + chi.rotate(&ri)
    }

    /// Fold angle θ (rad) of joint `joint` (must be a FlaredHinge):
    /// `R_rel = C^{GB_n}ᵀ C^{GA_child}` divided by its reference value; with `a' = −a`,
    /// `n1 = z ⟂ a'` and `n2 = a' × n1`, `θ = atan2(n2·(R_rel n1), n1·(R_rel n1))`.
    pub fn fold_angle(&self, q: &[f64], joint: usize) -> Result<f64, Error> {
        match self.joints.get(joint) {
            None => Err(Error::NoSuchJoint { joint, n_joints: self.joints.len() }),
            Some(Joint::Flared(h)) => Ok(h.fold_angle(&self.bodies, q)),
            Some(_) => Err(Error::NotAFlaredHinge { joint }),
        }
    }

    /// The hinge angle θ (rad) used by a hinge spring on joint `joint` (a ground hinge or a free
    /// flared hinge, with or without a spring): for a flared hinge the fold angle
    /// ([`fold_angle`](Self::fold_angle)), for a ground hinge the body's rotation about the hinge
    /// axis (right-handed), both zero in the reference configuration. Unlike `fold_angle` it is
    /// unwrapped against the angle of the last accepted step (docs/gebf.md §13), so it is
    /// continuous through ±180° and counts turns.
    pub fn hinge_angle(&self, q: &[f64], joint: usize) -> Result<f64, Error> {
        let j = self.joints.get(joint).ok_or(Error::NoSuchJoint { joint, n_joints: self.joints.len() })?;
        let principal = principal_angle(j, &self.bodies, q).ok_or(Error::NotAFreeHinge { joint })?;
        Ok(unwrap(principal, self.hinge_last[joint]))
    }

    /// Rate of the hinge angle of [`hinge_angle`](Self::hinge_angle), rad/s, at `q`, `v`.
    pub fn hinge_rate(&self, q: &[f64], v: &[f64], joint: usize) -> Result<f64, Error> {
        let j = self.joints.get(joint).ok_or(Error::NoSuchJoint { joint, n_joints: self.joints.len() })?;
        HingeSpring::angle_and_rate(j, &self.bodies, self.hinge_last[joint], q, v)
            .map(|(_, rate)| rate)
            .ok_or(Error::NotAFreeHinge { joint })
    }

    /// Set the angles the hinge angles are unwrapped against to the principal angles at `q`
    /// (in (−π, π]). The model does this itself after every accepted step; call it before
    /// integrating from a state that is not the continuation of the last step (a model reused
    /// for a new run). [`simulate::run`](crate::simulate::run) calls it at its start.
    pub fn reset_hinge_angles(&mut self, q: &[f64]) {
        for (j, last) in self.joints.iter().zip(self.hinge_last.iter_mut()) {
            *last = principal_angle(j, &self.bodies, q).unwrap_or(0.0);
        }
    }

    /// Power dissipated by the hinge dampers, `Σ c θ̇² ≥ 0`, W. Its time integral is the
    /// work the dampers remove: `E(t) + ∫ Σ c θ̇² dt` is conserved without external loads.
    pub fn dissipation_power(&self, q: &[f64], v: &[f64]) -> f64 {
        self.springs
            .iter()
            .filter(|s| s.damping != 0.0)
            .filter_map(|s| {
                let j = &self.joints[s.joint];
                HingeSpring::angle_and_rate(j, &self.bodies, self.hinge_last[s.joint], q, v)
                    .map(|(_, rate)| s.damping * rate * rate)
            })
            .sum()
    }

    /// Indices (into the joint list) of the flared hinges.
    pub fn flared_hinges(&self) -> Vec<usize> {
        self.joints.iter().enumerate().filter(|(_, j)| matches!(j, Joint::Flared(_))).map(|(i, _)| i).collect()
    }

    /// Kinetic, elastic and gravitational potential energy.
    pub fn energies(&self, q: &[f64], v: &[f64]) -> Energies {
        let mut e = Energies::default();
        let mut res = Vec24::zeros();
        for b in &self.bodies {
            let (r_a, chi) = b.frame_state(q);
            let c_ga = chi.to_rotation_matrix();
            for el in 0..b.n_elements {
                let st = ElementState::gather(b, el, q, Some(v), None);
                e.kinetic += add_element_inertia(&st, b, el, &mut res, None);
                e.elastic += add_elastic(
                    &st,
                    b.le,
                    &b.section,
                    self.options.n_gauss_stiffness,
                    b.element_twist(el),
                    &mut res,
                    None,
                );
                e.potential += element_potential(&st, b, el, &self.gravity, &r_a, &c_ga);
            }
        }
        for s in &self.springs {
            let j = &self.joints[s.joint];
            if let Some((theta, _)) = HingeSpring::angle_and_rate(j, &self.bodies, self.hinge_last[s.joint], q, v) {
                e.spring += s.energy(theta);
            }
        }
        e
    }

    /// Position-level joint violation: the Euclidean norm, over all joints, of (position gap in
    /// m, axis misalignment angle in rad [for clamps: the full relative rotation angle]).
    pub fn constraint_residual(&self, q: &[f64]) -> f64 {
        self.joints
            .iter()
            .map(|j| {
                let (g, a) = j.violation(&self.bodies, q);
                g * g + a * a
            })
            .sum::<f64>()
            .sqrt()
    }

    /// Per joint: (position gap, m; axis misalignment angle, rad).
    pub fn joint_violations(&self, q: &[f64]) -> Vec<(f64, f64)> {
        self.joints.iter().map(|j| j.violation(&self.bodies, q)).collect()
    }

    /// Largest nodal CRV norm (rad). The nodal rotations are relative to the body frame; the
    /// tangential operator is singular at 2π, so this should stay well below that.
    pub fn max_nodal_rotation(&self, q: &[f64]) -> f64 {
        let mut m: f64 = 0.0;
        for b in &self.bodies {
            for i in 1..b.n_nodes() {
                m = m.max(b.node_state(q, i).1.norm());
            }
        }
        m
    }

    /// Element matrix when a node's CRV was mapped to another branch: the mass, gyroscopic and
    /// stiffness parts are needed separately for the chain rule.
    fn mapped_element_matrix(&self, b: &Body, e: usize, st: &ElementState, g_a: &V3, c: MatrixCoefficients) -> Mat24 {
        let (mut m, mut g, mut k) = (Mat24::zeros(), Mat24::zeros(), Mat24::zeros());
        let mut res = Vec24::zeros();
        let mut scratch = Vec24::zeros();
        let unit = |c_m, c_c, c_k| MatrixCoefficients { c_m, c_c, c_k };
        add_element_inertia(st, b, e, &mut res, Some((&mut m, unit(1.0, 0.0, 0.0))));
        add_element_inertia(st, b, e, &mut scratch, Some((&mut g, unit(0.0, 1.0, 0.0))));
        add_element_inertia(st, b, e, &mut scratch, Some((&mut k, unit(0.0, 0.0, 1.0))));
        add_elastic(
            st,
            b.le,
            &b.section,
            self.options.n_gauss_stiffness,
            b.element_twist(e),
            &mut res,
            Some((&mut k, 1.0)),
        );
        add_element_gravity(st, b, e, g_a, &mut res, Some((&mut k, 1.0)));
        st.map_matrix(&res, &m, &g, &k, c)
    }

    /// The element loop behind the residual and the iteration matrix: `r = M v̇ + g` when `r` is
    /// given, `k += c_m ∂r/∂v̇ + c_c ∂r/∂v + c_k ∂r/∂q` when the matrix is given, both from one
    /// evaluation of each element (elements whose CRVs are mapped across π build the matrix by
    /// the chain rule and take the plain residual path).
    fn element_pass(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        v_dot: &[f64],
        mut r: Option<&mut [f64]>,
        mut matrix: Option<(MatrixCoefficients, &mut MatView<'_>)>,
    ) {
        if let Some(r) = r.as_deref_mut() {
            r.fill(0.0);
        }
        let ng = self.options.n_gauss_stiffness;
        let mut res = Vec24::zeros();
        let mut mat = Mat24::zeros();
        let mut st = ElementState::default();
        for b in &self.bodies {
            let g_a = self.gravity_in_frame(b, q);
            for e in 0..b.n_elements {
                res.as_mut_slice().fill(0.0);
                st.gather_into(b, e, q, Some(v), Some(v_dot));
                let mapped = st.is_mapped();
                let plain_residual = match &matrix {
                    None => true,
                    Some((coeffs, _)) if mapped => {
                        mat = self.mapped_element_matrix(b, e, &st, &g_a, *coeffs);
                        r.is_some()
                    }
                    Some((coeffs, _)) => {
                        mat.as_mut_slice().fill(0.0);
                        add_element_inertia(&st, b, e, &mut res, Some((&mut mat, *coeffs)));
                        // c_k = 0 leaves the stiffness out of the matrix, not out of the residual
                        let k_part = (coeffs.c_k != 0.0).then_some(coeffs.c_k);
                        add_elastic(
                            &st,
                            b.le,
                            &b.section,
                            ng,
                            b.element_twist(e),
                            &mut res,
                            k_part.map(|c| (&mut mat, c)),
                        );
                        add_element_gravity(&st, b, e, &g_a, &mut res, k_part.map(|c| (&mut mat, c)));
                        false
                    }
                };
                if plain_residual {
                    add_element_inertia(&st, b, e, &mut res, None);
                    add_elastic(&st, b.le, &b.section, ng, b.element_twist(e), &mut res, None);
                    add_element_gravity(&st, b, e, &g_a, &mut res, None);
                }
                if let Some(r) = r.as_deref_mut() {
                    st.map_residual(&mut res);
                    for (lr, gr, nr) in local_ranges(b, e) {
                        for (x, y) in r[gr..gr + nr].iter_mut().zip(&res.as_slice()[lr..lr + nr]) {
                            *x += y;
                        }
                    }
                }
                if let Some((_, k)) = matrix.as_mut() {
                    scatter_matrix(b, e, &mat, k);
                }
            }
        }
        if self.n_loaded > 0 {
            for (bi, b) in self.bodies.iter().enumerate() {
                for (i, l) in self.loads[bi].iter().enumerate().filter(|(_, l)| !l.is_zero()) {
                    if let Some(r) = r.as_deref_mut() {
                        add_load(b, i, l, self.load_scale, q, r);
                    }
                    if let Some((coeffs, k)) = matrix.as_mut()
                        && coeffs.c_k != 0.0
                    {
                        add_load_tangent(b, i, l, self.load_scale, q, coeffs.c_k, k);
                    }
                }
            }
        }
        for s in &self.springs {
            let matrix = matrix.as_mut().map(|(c, k)| (c.c_c, c.c_k, &mut **k));
            let j = &self.joints[s.joint];
            s.add(j, &self.bodies, self.hinge_last[s.joint], q, v, r.as_deref_mut(), matrix);
        }
        for th in &self.thrusts {
            let b = &self.bodies[th.body];
            let p = self.load_scale * th.magnitude(t);
            if let Some(r) = r.as_deref_mut() {
                th.add_residual(b, p, q, r);
            }
            if let Some((coeffs, k)) = matrix.as_mut() {
                th.add_tangent(b, p, q, coeffs.c_k, k);
            }
        }
    }

    /// Project `q` onto the joints' position-level constraints (each joint re-anchors and
    /// realigns its child body's frame, parents first), as the stabilisation after a time step
    /// does. The velocity-level joints let a static iteration drift off the joint by second-order
    /// amounts per update; a static solve that moves far (a continuation over tens of degrees
    /// of fold) projects after every update.
    pub fn project_joints(&self, q: &mut [f64]) {
        let n = self.n_dof();
        let (mut a, mut b, mut c) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for &j in &self.projection_order {
            self.joints[j].project(&self.bodies, q, [&mut a, &mut b, &mut c]);
        }
    }

    /// Rescale every nodal CRV with |psi| > π to the equivalent one below π, transforming its
    /// rates (`rates = (v, v_dot, a)`) so that the angular velocity and acceleration are kept.
    /// Elements then map their end nodes back onto the middle node's branch (exact chain rule),
    /// so rotations of more than π relative to the body frame are handled; T(psi) is never
    /// evaluated near its singularity at 2π.
    pub fn rescale_rotations(&self, q: &mut [f64], rates: Option<(&mut [f64], &mut [f64], &mut [f64])>) {
        let mut rates = rates;
        for b in &self.bodies {
            for i in 1..b.n_nodes() {
                let (_, psi) = b.node_state(q, i);
                let Some(new) = crate::crv::rescale(&psi) else { continue };
                let k = b.node_coord(i).expect("i ≥ 1") + 3;
                q[k..k + 3].copy_from_slice(new.as_slice());
                if let Some((v, vd, a)) = rates.as_mut() {
                    let d = b.node_dof(i).expect("i ≥ 1") + 3;
                    let get = |x: &[f64]| V3::new(x[d], x[d + 1], x[d + 2]);
                    let (pd, pdd, pa) = (get(v), get(vd), get(a));
                    let pd_new = crate::crv::rescale_rates(&psi, &new, &pd);
                    let pdd_new = crate::crv::rescale_accelerations(&psi, &new, &pd, &pd_new, &pdd);
                    let pa_new = crate::crv::rescale_accelerations(&psi, &new, &pd, &pd_new, &pa);
                    v[d..d + 3].copy_from_slice(pd_new.as_slice());
                    vd[d..d + 3].copy_from_slice(pdd_new.as_slice());
                    a[d..d + 3].copy_from_slice(pa_new.as_slice());
                }
            }
        }
    }

    fn gravity_in_frame(&self, b: &Body, q: &[f64]) -> V3 {
        let (_, chi) = b.frame_state(q);
        chi.conjugate().rotate(&self.gravity) * self.load_scale
    }
}

impl ConstrainedSystem for Model {
    fn n_coords(&self) -> usize {
        self.n_coords
    }

    fn n_dof(&self) -> usize {
        self.n_dof
    }

    fn n_velocity_constraints(&self) -> usize {
        self.n_rows
    }

    /// Nodal coordinates are updated additively. A frame is updated on SE(3)-like lines:
    /// `χ ← χ ⊗ exp(δθ/2)` and `r_A ← r_A + C^{GA}(χ ⊗ exp(δθ/4)) δr`, i.e. the translation
    /// increment (in A) is rotated to global with the orientation at the *midpoint* of the
    /// rotation increment. The integrator calls this with `δ = h Δ`, `Δ` the step's mean
    /// velocity to O(h²); since `∫ C^{GA} v_A dt = h C^{GA}(t_{n+½}) v_A(t_{n+½}) + O(h³)`
    /// and the midpoint orientation is `C^{GA}_n exp(h Δω/2) + O(h³)`, the frame position keeps
    /// the second-order accuracy of the rest of the scheme (a test checks the observed order).
    /// Rotating with the start orientation instead would make it first order.
    fn retract_inplace(&self, q: &[f64], dq: &[f64], q_out: &mut [f64]) {
        for b in &self.bodies {
            let (c0, d0) = (b.coord0, b.dof0);
            let nn = 12 * b.n_elements;
            for k in 0..nn {
                q_out[c0 + k] = q[c0 + k] + dq[d0 + k];
            }
            let fc = b.frame_coord();
            let fd = b.frame_dof();
            let dr = V3::new(dq[fd], dq[fd + 1], dq[fd + 2]);
            let dth = V3::new(dq[fd + 3], dq[fd + 4], dq[fd + 5]);
            let chi = Quaternion::from_slice(&q[fc + 3..fc + 7]);
            let mid = chi.mul(&Quaternion::from_rotation_vector(&(dth * 0.5)));
            let r = V3::new(q[fc], q[fc + 1], q[fc + 2]) + mid.rotate(&dr);
            q_out[fc..fc + 3].copy_from_slice(r.as_slice());
            chi.retract(&dth).write_to(&mut q_out[fc + 3..fc + 7]);
        }
    }

    fn residual_inplace(&self, t: f64, q: &[f64], v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        self.element_pass(t, q, v, v_dot, Some(r), None);
    }

    fn iteration_matrix_inplace(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        v_dot: &[f64],
        c_m: f64,
        c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        self.element_pass(t, q, v, v_dot, None, Some((MatrixCoefficients { c_m, c_c, c_k }, k)));
    }

    /// One pass over the elements: the element routines produce the residual while they build
    /// the matrix.
    fn residual_and_iteration_matrix_inplace(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        v_dot: &[f64],
        r: &mut [f64],
        c_m: f64,
        c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        self.element_pass(t, q, v, v_dot, Some(r), Some((MatrixCoefficients { c_m, c_c, c_k }, k)));
    }

    fn psi_inplace(&self, _t: f64, q: &[f64], v: &[f64], psi: &mut [f64]) {
        for (j, row) in self.joints.iter().zip(&self.joint_row) {
            j.psi(&self.bodies, q, v, &mut psi[*row..*row + j.n_rows()]);
        }
    }

    fn psi_v_inplace(&self, _t: f64, q: &[f64], m: &mut MatView<'_>) {
        for (j, row) in self.joints.iter().zip(&self.joint_row) {
            j.add_b(&self.bodies, q, m, *row);
        }
    }

    fn psi_q_inplace(&self, _t: f64, q: &[f64], v: &[f64], m: &mut MatView<'_>) {
        for (j, row) in self.joints.iter().zip(&self.joint_row) {
            j.add_psi_q(&self.bodies, q, v, m, *row);
        }
    }

    fn constraint_force_tangent_inplace(
        &self,
        _t: f64,
        q: &[f64],
        _lambda: &[f64],
        mu: &[f64],
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        for (j, row) in self.joints.iter().zip(&self.joint_row) {
            j.add_force_tangent(&self.bodies, q, &mu[*row..*row + j.n_rows()], c_k, k);
        }
    }

    fn post_step(&mut self, t: f64, q: &mut [f64], v: &mut [f64], v_dot: &mut [f64], a: &mut [f64]) {
        self.rescale_rotations(q, Some((&mut *v, &mut *v_dot, &mut *a)));
        if self.options.stabilization {
            for &j in &self.projection_order {
                self.joints[j].project(&self.bodies, q, [&mut *v, &mut *v_dot, &mut *a]);
            }
        }
        if self.options.conserve_momentum {
            self.project_momentum(t, q, v);
        }
        // The accepted angles, for the unwrapping in the next step (the rescaling and the
        // projection above keep every rotation, so they do not move the angle).
        for (j, last) in self.joints.iter().zip(self.hinge_last.iter_mut()) {
            if let Some(p) = principal_angle(j, &self.bodies, q) {
                *last = unwrap(p, *last);
            }
        }
    }

    /// Each body's nodal unknowns form a band block (an element couples 3 consecutive nodes:
    /// half-bandwidth 17); the frame velocities and the joint rows form the border.
    fn matrix_structure(&self) -> Option<genalpha::BandedBorder> {
        // Nodes of six unknowns (R, psi); a three-node element couples nodes at most two apart.
        Some(genalpha::BandedBorder {
            blocks: self.bodies.iter().map(|b| (b.dof0, 12 * b.n_elements, 17)).collect(),
            node_bandwidth: Some(2),
        })
    }

    /// Positions in m weigh 1; rotations weigh the body length (a rotation δ moves the far end
    /// of the body by about L·δ).
    fn increment_weight(&self, i: usize) -> f64 {
        for b in &self.bodies {
            if i < b.dof0 + b.n_dof() {
                let k = i - b.dof0;
                let is_rotation = (k % 6) >= 3;
                return if is_rotation { b.length } else { 1.0 };
            }
        }
        1.0
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

    /// The power of the thrusts `Σ F · ṙ` at time `t`, coordinates `q` and velocities `v`, W.
    pub fn thrust_power(&self, t: f64, q: &[f64], v: &[f64]) -> f64 {
        self.thrusts.iter().map(|th| th.power(&self.bodies[th.body], self.load_scale * th.magnitude(t), q, v)).sum()
    }
}
