//! Property tests (proptest) of the flared hinge written as a linear holonomic constraint on the
//! nodal coordinates (paper eq. 5: `r¹ = r²`, `a¹ = a²`, `a = sin β r_x + cos β r_y`), of its
//! exact elimination (the ODE path, `q = B z + q_p`), and of the objectivity of the elastic
//! force, over random geometry (body frames, lengths, element counts, flare angle β including
//! the ends ±90° and 0) and random states.
//!
//! Inputs are plain numbers and angles so that a shrunk counterexample reads directly: a
//! rotation is its rotation vector `[x, y, z]` (rad), and the high-dimensional random vectors
//! (general velocities, perturbations) come from a `seed` through a fixed generator.
//!
//! Scenes: a *free pair* (two bodies joined only by the flared hinge, so that any rigid motion
//! of the assembly is admissible) and a *pendulum* (the same plus a ground hinge about a random
//! axis at body 1's start).

use ancf::{BodySpec, Curvature, JointSpec, Model, Options, RigidPose, SolvePath, samples};
use genalpha::{ConstrainedSystem, DenseMatrix};
use nalgebra::{DMatrix, Matrix3, Rotation3, Unit, Vector3};
use proptest::prelude::*;
use std::f64::consts::FRAC_PI_2;

type V3 = Vector3<f64>;
type M3 = Matrix3<f64>;

fn config() -> ProptestConfig {
    ProptestConfig { cases: 256, ..ProptestConfig::default() }
}

/// β in [−π/2, π/2], with the special values 0 and ±π/2 drawn often.
fn beta() -> impl Strategy<Value = f64> {
    prop_oneof![1 => Just(0.0), 1 => Just(FRAC_PI_2), 1 => Just(-FRAC_PI_2), 7 => -FRAC_PI_2..=FRAC_PI_2]
}

/// A rotation vector (rad) with components in [−2, 2]: any rotation up to ~3.5 rad.
fn rotvec() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-2.0..2.0f64)
}

/// A vector with components in [−1, 1].
fn vec3() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-1.0..1.0f64)
}

fn rot(v: [f64; 3]) -> M3 {
    Rotation3::from_scaled_axis(V3::from(v)).into_inner()
}

fn axis_angle(axis: &V3, angle: f64) -> M3 {
    Rotation3::from_axis_angle(&Unit::new_normalize(*axis), angle).into_inner()
}

/// `n` numbers in [−1, 1] from `seed` (SplitMix64).
fn noise(seed: u64, n: usize) -> Vec<f64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
        .collect()
}

/// A two-body scene with its hinge data in the reference configuration.
struct Scene {
    bodies: Vec<BodySpec>,
    joints: Vec<JointSpec>,
    /// Hinge axis a = F_P (sin β, cos β, 0), global, reference.
    a0: V3,
    /// Hinge point (parent's end), global, reference.
    hinge0: V3,
}

/// Geometry from plain numbers: body 1 starts at `start` with frame `rot(frame)`, body 2 starts
/// at body 1's end with the frame turned further by `rot(kink)`; `ground`: a ground hinge about
/// `ground_axis` at body 1's start (joint 0, the flared hinge is then joint 1).
#[allow(clippy::too_many_arguments)] // plain numbers on purpose: readable counterexamples
fn scene(
    beta: f64,
    frame: [f64; 3],
    kink: [f64; 3],
    lengths: (f64, f64),
    n_el: (usize, usize),
    start: [f64; 3],
    ground_axis: Option<[f64; 3]>,
    c: f64,
) -> Scene {
    let fp = rot(frame);
    let fc = fp * rot(kink);
    let start = V3::from(start);
    let hinge0 = start + fp.column(0) * lengths.0;
    let body = |name: &str, start, length, frame, n_elements| BodySpec {
        name: name.into(),
        start,
        length,
        frame,
        section: samples::paper_section(c),
        n_elements,
        point_masses: Vec::new(),
        twist: ancf::Twist::none(),
    };
    let bodies = vec![body("p", start, lengths.0, fp, n_el.0), body("c", hinge0, lengths.1, fc, n_el.1)];
    let mut joints = Vec::new();
    if let Some(axis) = ground_axis {
        joints.push(JointSpec::GroundHinge { body: 0, axis: V3::from(axis) });
    }
    joints.push(JointSpec::FlaredHinge { parent: 0, child: 1, beta });
    Scene { bodies, joints, a0: fp * V3::new(beta.sin(), beta.cos(), 0.0), hinge0 }
}

fn model(s: &Scene, path: SolvePath) -> Model {
    Model::new(&s.bodies, &s.joints, V3::zeros(), Options { path, ..Default::default() }).expect("valid scene")
}

/// Rigid motion of the folded assembly: body 1 rotated by `r` about its start, which moves to
/// `t`, with velocity `v1` (of its start) and angular velocity `w1`; body 2 in addition turned
/// by the fold angle θ about the hinge line (right-hand rule about −a) at the fold rate θ̇.
struct Motion {
    r: M3,
    t: V3,
    theta: f64,
    w1: V3,
    v1: V3,
    theta_dot: f64,
}

impl Motion {
    fn at_rest(r: M3, t: V3, theta: f64) -> Self {
        Self { r, t, theta, w1: V3::zeros(), v1: V3::zeros(), theta_dot: 0.0 }
    }
    fn hinge(&self, s: &Scene) -> V3 {
        self.t + self.r * (s.hinge0 - s.bodies[0].start)
    }
    fn axis(&self, s: &Scene) -> V3 {
        self.r * s.a0
    }
    fn poses(&self, s: &Scene) -> [RigidPose; 2] {
        let h = self.hinge(s);
        let p1 = RigidPose { rotation: self.r, translation: self.t, angular_velocity: self.w1, velocity: self.v1 };
        let p2 = RigidPose {
            rotation: self.r * axis_angle(&(-s.a0), self.theta),
            translation: h,
            angular_velocity: self.w1 - self.axis(s) * self.theta_dot,
            velocity: self.v1 + self.w1.cross(&(h - self.t)),
        };
        [p1, p2]
    }
}

/// A body at rest, rotated by `rot(r)` with its start at `t`.
fn still(r: [f64; 3], t: [f64; 3]) -> RigidPose {
    RigidPose { rotation: rot(r), translation: V3::from(t), angular_velocity: V3::zeros(), velocity: V3::zeros() }
}

fn phi(m: &Model, q: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; m.n_holonomic()];
    m.phi_inplace(0.0, q, &mut out);
    out
}

fn phi_q(m: &Model, q: &[f64]) -> DMatrix<f64> {
    let mut j = DenseMatrix::zeros(m.n_holonomic(), m.n_dof());
    m.phi_q_inplace(0.0, q, &mut j.view());
    DMatrix::from_fn(j.n_rows(), j.n_cols(), |r, c| j.get(r, c))
}

fn amax(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, y| m.max(y.abs()))
}

fn vec_of(x: &[f64], i: usize) -> V3 {
    V3::new(x[i], x[i + 1], x[i + 2])
}

/// Full index of node `node`'s block (0 r, 1 r_x, 2 r_y, 3 r_z) of body `body` (12 per node,
/// bodies in order).
fn dof(s: &Scene, body: usize, node: usize, block: usize) -> usize {
    let first: usize = s.bodies[..body].iter().map(|b| 12 * (b.n_elements + 1)).sum();
    first + 12 * node + 3 * block
}

/// Singular values, largest first.
fn singular_values(a: &DMatrix<f64>) -> Vec<f64> {
    let mut s: Vec<f64> = a.clone().svd(false, false).singular_values.iter().copied().collect();
    s.sort_by(|x, y| y.total_cmp(x));
    s
}

proptest! {
    #![proptest_config(config())]

    /// Φ(q) = 0 to round-off for any rigid motion of the assembly with any fold angle about the
    /// hinge axis; the fold-angle sensor reads θ and the position residual is zero; the ODE
    /// path's `B z + q_p` reproduces the same coordinates.
    #[test]
    fn rigid_fold_satisfies_the_hinge_equations(
        beta in beta(), frame in rotvec(), kink in prop::array::uniform3(-0.8..0.8f64),
        l1 in 0.2..2.0f64, l2 in 0.2..2.0f64, n1 in 1..=3usize, n2 in 1..=3usize, start in vec3(),
        motion in rotvec(), shift in vec3(), theta in -3.0..3.0f64,
    ) {
        let s = scene(beta, frame, kink, (l1, l2), (n1, n2), start, None, 1.0);
        let m = model(&s, SolvePath::Dae);
        let mo = Motion::at_rest(rot(motion), V3::from(shift) * 3.0, theta);
        let poses = mo.poses(&s);
        let (q, _) = m.rigid_full_state(&poses).unwrap();
        let p = phi(&m, &q);
        prop_assert!(amax(&p) < 1e-13, "|Φ| = {:e}", amax(&p));
        prop_assert!(m.constraint_residual(&q) < 1e-13, "residual {:e}", m.constraint_residual(&q));
        let fold = m.fold_angle(&q, 0).unwrap();
        prop_assert!((fold - theta).abs() < 1e-12, "fold {fold} vs θ {theta}");

        let ode = model(&s, SolvePath::Ode);
        let st = ode.rigid_state(&poses).unwrap();
        let full = ode.full_coordinates(&st.q);
        let err = full.iter().zip(&q).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        prop_assert!(err < 1e-13, "ODE B z + q_p differs from the pose by {err:e}");
        prop_assert!((ode.fold_angle(&st.q, 0).unwrap() - theta).abs() < 1e-12);
    }

    /// A general (flexible) velocity in the null space of Φ_q moves the hinge line identically
    /// on both sides: every point `r + σ a` of the line, seen through either body's nodal
    /// tangent map (parent end: `r¹ + σ(sin β r¹_x + cos β r¹_y)`; child start: the same line in
    /// the child's section coordinates `σ F_Cᵀ a`), has the same velocity.
    #[test]
    fn null_space_velocities_move_the_hinge_line_together(
        beta in beta(), frame in rotvec(), kink in prop::array::uniform3(-0.8..0.8f64),
        n1 in 1..=3usize, n2 in 1..=2usize, motion in rotvec(), theta in -3.0..3.0f64,
        sigma in -2.0..2.0f64, seed in any::<u64>(),
    ) {
        let s = scene(beta, frame, kink, (0.7, 0.4), (n1, n2), [0.1, -0.2, 0.3], None, 1.0);
        let m = model(&s, SolvePath::Dae);
        let mo = Motion::at_rest(rot(motion), V3::zeros(), theta);
        let (q, _) = m.rigid_full_state(&mo.poses(&s)).unwrap();
        let j = phi_q(&m, &q);
        let w = DMatrix::from_column_slice(m.n_dof(), 1, &noise(seed, m.n_dof()));
        // v = w − Φ_qᵀ (Φ_q Φ_qᵀ)⁻¹ Φ_q w
        let jjt = &j * j.transpose();
        let y = jjt.lu().solve(&(&j * &w)).expect("Φ_q has full row rank");
        let v = &w - j.transpose() * y;
        let v = v.as_slice();
        let a_local_p = V3::new(beta.sin(), beta.cos(), 0.0);
        let a_local_c = s.bodies[1].frame.transpose() * (s.bodies[0].frame * a_local_p);
        let line_velocity = |body: usize, node: usize, alpha: &V3| {
            vec_of(v, dof(&s, body, node, 0))
                + (1..4).map(|b| vec_of(v, dof(&s, body, node, b)) * (sigma * alpha[b - 1])).sum::<V3>()
        };
        let vp = line_velocity(0, n1, &a_local_p);
        let vc = line_velocity(1, 0, &a_local_c);
        prop_assert!((vp - vc).norm() < 1e-12 * (1.0 + vp.norm()), "{vp} vs {vc}");
        // and the velocity is not trivially zero there
        prop_assert!(vp.norm() > 1e-6);
    }

    /// Restricted to rigid velocities of the two bodies (12 numbers: v₁, ω₁, v₂, ω₂), Φ_q has
    /// rank 5: the admissible motions are the 6 rigid motions of the assembly plus one, and every
    /// admissible motion is a relative rotation about the hinge axis only (same hinge-point
    /// velocity, ω₂ − ω₁ ∥ a). Conversely a relative linear velocity δv at the hinge and a
    /// relative angular velocity δω violate the rows by exactly `√(|δv|² + |δω × a|²)`.
    #[test]
    fn rigid_null_space_is_a_rotation_about_the_hinge_axis(
        beta in beta(), frame in rotvec(), kink in prop::array::uniform3(-0.8..0.8f64),
        l1 in 0.2..2.0f64, l2 in 0.2..2.0f64, motion in rotvec(), shift in vec3(), theta in -3.0..3.0f64,
        w1 in vec3(), v1 in vec3(), dw in vec3(), dv in vec3(),
    ) {
        let s = scene(beta, frame, kink, (l1, l2), (2, 1), [0.0; 3], None, 1.0);
        let m = model(&s, SolvePath::Dae);
        let mo = Motion::at_rest(rot(motion), V3::from(shift), theta);
        let base = mo.poses(&s);
        let (q, _) = m.rigid_full_state(&base).unwrap();
        let j = phi_q(&m, &q);
        // G: rigid velocities (v_b, ω_b) → nodal velocities.
        let n = m.n_dof();
        let mut g = DMatrix::zeros(n, 12);
        for col in 0..12 {
            let mut p = base;
            for x in &mut p {
                x.velocity = V3::zeros();
                x.angular_velocity = V3::zeros();
            }
            let (b, k) = (col / 6, col % 6);
            if k < 3 { p[b].velocity[k] = 1.0 } else { p[b].angular_velocity[k - 3] = 1.0 }
            let (_, v) = m.rigid_full_state(&p).unwrap();
            g.set_column(col, &DMatrix::from_column_slice(n, 1, &v).column(0));
        }
        let mut k = DMatrix::zeros(12, 12);
        k.rows_mut(0, j.nrows()).copy_from(&(&j * &g));
        let svd = k.svd(false, true);
        let vt = svd.v_t.expect("v_t requested");
        let sv = &svd.singular_values;
        let smax = sv.max();
        let rank = sv.iter().filter(|&&x| x > 1e-9 * smax).count();
        prop_assert_eq!(rank, 5, "singular values {:?}", sv.as_slice());
        let (h, a) = (mo.hinge(&s), mo.axis(&s));
        let mut n_fold = 0;
        for (i, &sigma) in sv.iter().enumerate() {
            if sigma > 1e-9 * smax { continue; }
            let c: Vec<f64> = vt.row(i).iter().copied().collect();
            let (v1c, w1c, v2c, w2c) = (vec_of(&c, 0), vec_of(&c, 3), vec_of(&c, 6), vec_of(&c, 9));
            let dw_rel = w2c - w1c;
            let gap = v1c + w1c.cross(&(h - mo.t)) - v2c;
            prop_assert!(dw_rel.cross(&a).norm() < 1e-10, "relative rotation {dw_rel} not about a = {a}");
            prop_assert!(gap.norm() < 1e-10, "hinge points separate at {gap}");
            if dw_rel.norm() > 1e-3 { n_fold += 1; }
        }
        prop_assert!(n_fold >= 1, "no admissible fold motion found");

        // Violation in proportion.
        let (w1, dw, dv) = (V3::from(w1), V3::from(dw), V3::from(dv));
        let mut p = base;
        p[0].angular_velocity = w1;
        p[0].velocity = V3::from(v1);
        p[1].angular_velocity = w1 + dw;
        p[1].velocity = p[0].velocity + w1.cross(&(h - mo.t)) + dv;
        let (_, v) = m.rigid_full_state(&p).unwrap();
        let psi = &j * DMatrix::from_column_slice(n, 1, &v);
        let expected = (dv.norm_squared() + dw.cross(&a).norm_squared()).sqrt();
        prop_assert!((psi.norm() - expected).abs() < 1e-12 * (1.0 + expected), "{} vs {expected}", psi.norm());
    }

    /// Φ_q is the same matrix at any two configurations and equals central differences of Φ;
    /// Φ is exactly linear: Φ(q + δ) − Φ(q) = Φ_q δ for large δ.
    #[test]
    fn constraint_jacobian_is_constant_and_equals_finite_differences(
        beta in beta(), frame in rotvec(), kink in prop::array::uniform3(-0.8..0.8f64),
        n1 in 1..=2usize, n2 in 1..=2usize, ground in prop::option::of(vec3()), seed in any::<u64>(),
    ) {
        let ground = ground.filter(|g| V3::from(*g).norm() > 0.1);
        let s = scene(beta, frame, kink, (0.5, 0.5), (n1, n2), [0.0; 3], ground, 1.0);
        let m = model(&s, SolvePath::Dae);
        let n = m.n_dof();
        let q0 = m.initial_state().q;
        let d1 = noise(seed, n);
        let d2 = noise(seed ^ 0xABCD, n);
        let q1: Vec<f64> = q0.iter().zip(&d1).map(|(a, b)| a + 0.2 * b).collect();
        let q2: Vec<f64> = q0.iter().zip(&d2).map(|(a, b)| a + 3.0 * b).collect();
        let j1 = phi_q(&m, &q1);
        prop_assert_eq!(&j1, &phi_q(&m, &q2));
        let h = 1e-6;
        let mut fd = DMatrix::zeros(m.n_holonomic(), n);
        for c in 0..n {
            let (mut qp, mut qm) = (q1.clone(), q1.clone());
            qp[c] += h;
            qm[c] -= h;
            let (pp, pm) = (phi(&m, &qp), phi(&m, &qm));
            for r in 0..pp.len() {
                fd[(r, c)] = (pp[r] - pm[r]) / (2.0 * h);
            }
        }
        let err = (&fd - &j1).amax();
        prop_assert!(err < 1e-9, "max |Φ_q − FD| = {err:e}");
        let lin = DMatrix::from_column_slice(m.n_holonomic(), 1, &phi(&m, &q2))
            - DMatrix::from_column_slice(m.n_holonomic(), 1, &phi(&m, &q1));
        let delta = DMatrix::from_iterator(n, 1, q2.iter().zip(&q1).map(|(a, b)| a - b));
        let err = (lin - &j1 * delta).amax();
        prop_assert!(err < 1e-12, "Φ is not linear: {err:e}");
    }

    /// The ODE path's velocity transformation B spans exactly the null space of Φ_q: Φ_q B = 0,
    /// B has full column rank (σ_min ≥ 1: it holds an identity on the independent coordinates),
    /// and its column count is n − rank Φ_q; the particular solution satisfies the joints for
    /// any z. With and without a ground hinge.
    #[test]
    fn ode_basis_spans_exactly_the_null_space(
        beta in beta(), frame in rotvec(), kink in prop::array::uniform3(-0.8..0.8f64),
        n1 in 1..=2usize, n2 in 1..=2usize, ground in prop::option::of(vec3()), seed in any::<u64>(),
    ) {
        let ground = ground.filter(|g| V3::from(*g).norm() > 0.1);
        let s = scene(beta, frame, kink, (0.5, 0.8), (n1, n2), [0.3, 0.0, -0.1], ground, 1.0);
        let (dae, ode) = (model(&s, SolvePath::Dae), model(&s, SolvePath::Ode));
        let (n, nz) = (dae.n_dof(), ode.n_dof());
        let j = phi_q(&dae, &dae.initial_state().q);
        let rank_phi = singular_values(&j).iter().filter(|&&x| x > 1e-10).count();
        prop_assert_eq!(rank_phi, j.nrows(), "the joint rows must be independent");
        prop_assert_eq!(nz, n - rank_phi);
        let mut b = DMatrix::zeros(n, nz);
        let mut e = vec![0.0; nz];
        let mut col = vec![0.0; n];
        for c in 0..nz {
            e.iter_mut().for_each(|x| *x = 0.0);
            e[c] = 1.0;
            ode.full_velocities_inplace(&e, &mut col);
            b.set_column(c, &DMatrix::from_column_slice(n, 1, &col).column(0));
        }
        let jb = (&j * &b).amax();
        prop_assert!(jb < 1e-14, "|Φ_q B| = {jb:e}");
        let sv = singular_values(&b);
        prop_assert!(sv[nz - 1] >= 1.0 - 1e-12, "σ_min(B) = {}", sv[nz - 1]);
        let z: Vec<f64> = noise(seed, nz).iter().map(|x| 2.0 * x).collect();
        let q = ode.full_coordinates(&z);
        let p = phi(&dae, &q);
        prop_assert!(amax(&p) < 1e-13, "|Φ(B z + q_p)| = {:e}", amax(&p));
    }

    /// The ODE path presents the same physics: for a moving folded pendulum, the reduced state
    /// of `rigid_state` expands to the DAE coordinates and velocities, the sensors and energies
    /// agree, and the reduced residual is `Bᵀ` times the DAE residual (with gravity, random
    /// accelerations).
    #[test]
    fn ode_path_reproduces_the_dae_path(
        beta in beta(), frame in rotvec(), ground_axis in vec3(), phi1 in -3.0..3.0f64,
        theta in -3.0..3.0f64, phi1_dot in -5.0..5.0f64, theta_dot in -5.0..5.0f64, seed in any::<u64>(),
    ) {
        prop_assume!(V3::from(ground_axis).norm() > 0.1);
        let s = scene(beta, frame, [0.0; 3], (0.5, 0.5), (2, 2), [0.0; 3], Some(ground_axis), 1.0);
        let g = V3::new(0.0, 0.0, -9.8);
        let opts = |path| Options { path, ..Default::default() };
        let dae = Model::new(&s.bodies, &s.joints, g, opts(SolvePath::Dae)).unwrap();
        let ode = Model::new(&s.bodies, &s.joints, g, opts(SolvePath::Ode)).unwrap();
        let axis = V3::from(ground_axis).normalize();
        let mo = Motion {
            r: axis_angle(&axis, phi1), t: V3::zeros(), theta, w1: axis * phi1_dot, v1: V3::zeros(), theta_dot,
        };
        let poses = mo.poses(&s);
        let sd = dae.rigid_state(&poses).unwrap();
        let so = ode.rigid_state(&poses).unwrap();
        prop_assert!(dae.constraint_residual(&sd.q) < 1e-13);
        let jv = &phi_q(&dae, &sd.q) * DMatrix::from_column_slice(sd.v.len(), 1, &sd.v);
        prop_assert!(jv.amax() < 1e-13, "Φ_q v = {:e}", jv.amax());
        let n = dae.n_dof();
        let mut vf = vec![0.0; n];
        ode.full_velocities_inplace(&so.v, &mut vf);
        let qf = ode.full_coordinates(&so.q);
        for (x, y) in qf.iter().zip(&sd.q).chain(vf.iter().zip(&sd.v)) {
            prop_assert!((x - y).abs() < 1e-12, "{x} vs {y}");
        }
        let (ed, eo) = (dae.energies(&sd.q, &sd.v), ode.energies(&so.q, &so.v));
        prop_assert!((ed.kinetic - eo.kinetic).abs() < 1e-12 * (1.0 + ed.kinetic));
        prop_assert!((ed.potential - eo.potential).abs() < 1e-12 * (1.0 + ed.potential.abs()));
        prop_assert!((dae.fold_angle(&sd.q, 1).unwrap() - theta).abs() < 1e-12);
        prop_assert!((ode.fold_angle(&so.q, 1).unwrap() - theta).abs() < 1e-12);
        prop_assert!((dae.tip_position(&sd.q) - ode.tip_position(&so.q)).norm() < 1e-13);

        let zdd = noise(seed, ode.n_dof());
        let mut add = vec![0.0; n];
        ode.full_velocities_inplace(&zdd, &mut add);
        let (mut rd, mut ro) = (vec![0.0; n], vec![0.0; ode.n_dof()]);
        dae.residual_inplace(0.0, &sd.q, &sd.v, &add, &mut rd);
        ode.residual_inplace(0.0, &so.q, &so.v, &zdd, &mut ro);
        let mut btr = vec![0.0; ode.n_dof()];
        let mut col = vec![0.0; n];
        let mut e = vec![0.0; ode.n_dof()];
        for (c, x) in btr.iter_mut().enumerate() {
            e.iter_mut().for_each(|y| *y = 0.0);
            e[c] = 1.0;
            ode.full_velocities_inplace(&e, &mut col);
            *x = col.iter().zip(&rd).map(|(a, b)| a * b).sum();
        }
        // round-off of the elastic force (~1e-15 EA per entry) dominates at rigid states
        let tol = 1e-12 * (amax(&rd) + s.bodies[0].section.ea);
        let err = ro.iter().zip(&btr).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        prop_assert!(err < tol, "ODE residual ≠ Bᵀ DAE residual: {err:e} (tolerance {tol:e})");
    }

    /// Objectivity: any rigid motion of each body (joints not enforced) leaves the elastic
    /// energy and the elastic force at zero, for every curvature measure, on both paths (the
    /// ODE path's `Bᵀ f_el` at the independent part of a pose that satisfies the joints).
    #[test]
    fn rigid_motions_have_zero_elastic_energy_and_force(
        beta in beta(), frame in rotvec(), kink in prop::array::uniform3(-0.8..0.8f64),
        l1 in 0.2..2.0f64, l2 in 0.2..2.0f64, n1 in 1..=3usize, n2 in 1..=3usize,
        c in 0.01..1.0f64, r1 in rotvec(), t1 in vec3(), r2 in rotvec(), t2 in vec3(), theta in -3.0..3.0f64,
    ) {
        let s = scene(beta, frame, kink, (l1, l2), (n1, n2), [0.0; 3], None, c);
        let ea = s.bodies[0].section.ea;
        for curvature in [Curvature::Hybrid, Curvature::Kirchhoff, Curvature::Mixed] {
            let options = Options { curvature, ..Default::default() };
            let m = Model::new(&s.bodies, &s.joints, V3::zeros(), options).unwrap();
            let poses = [still(r1, t1), still(r2, t2)];
            let (q, _) = m.rigid_full_state(&poses).unwrap();
            let n = m.n_dof();
            let mut f = vec![0.0; n];
            m.residual_inplace(0.0, &q, &vec![0.0; n], &vec![0.0; n], &mut f);
            prop_assert!(amax(&f) < 1e-12 * ea, "{curvature:?}: |f_el| = {:e} N (EA = {ea:e})", amax(&f));
            let u = m.energies(&q, &vec![0.0; n]).elastic;
            prop_assert!(u.abs() < 1e-26 * ea, "{curvature:?}: U = {u:e} J");
        }
        let ode = model(&s, SolvePath::Ode);
        let st = ode.rigid_state(&Motion::at_rest(rot(r1), V3::from(t1), theta).poses(&s)).unwrap();
        let nz = ode.n_dof();
        let mut f = vec![0.0; nz];
        ode.residual_inplace(0.0, &st.q, &st.v, &vec![0.0; nz], &mut f);
        prop_assert!(amax(&f) < 1e-12 * ea, "ODE: |Bᵀ f_el| = {:e} N", amax(&f));
        prop_assert!(ode.energies(&st.q, &st.v).elastic.abs() < 1e-26 * ea);
    }

    /// Objectivity of a *deformed* state: a rigid motion superposed on an arbitrary nodal
    /// configuration leaves the elastic energy unchanged and rotates the elastic force
    /// (`f(R q + t) = R f(q)` node block by node block). The deformation is at least 1e-3 of
    /// the element: the energy is compared relatively, and the strains' round-off (about ε over
    /// the amplitude, relative) would exceed 1e-10 below about 1e-6; the undeformed states are
    /// the rigid-motion property's above.
    #[test]
    fn superposed_rigid_motion_keeps_the_elastic_energy_and_rotates_the_force(
        r in rotvec(), t in vec3(), seed in any::<u64>(), amplitude in 1e-3..0.05f64,
    ) {
        let s = scene(0.3, [0.0; 3], [0.0; 3], (0.5, 0.5), (2, 2), [0.0; 3], None, 1.0);
        for curvature in [Curvature::Hybrid, Curvature::Kirchhoff, Curvature::Mixed] {
            let options = Options { curvature, ..Default::default() };
            let m = Model::new(&s.bodies, &s.joints, V3::zeros(), options).unwrap();
            let n = m.n_dof();
            let q: Vec<f64> = m.initial_state().q.iter().zip(noise(seed, n)).map(|(a, b)| a + amplitude * b).collect();
            let (rm, t) = (rot(r), V3::from(t));
            let mut q2 = q.clone();
            for blk in (0..n).step_by(3) {
                let x = rm * vec_of(&q, blk) + if blk % 12 == 0 { t } else { V3::zeros() };
                q2[blk..blk + 3].copy_from_slice(x.as_slice());
            }
            let zeros = vec![0.0; n];
            let (u1, u2) = (m.energies(&q, &zeros).elastic, m.energies(&q2, &zeros).elastic);
            prop_assert!((u1 - u2).abs() <= 1e-10 * u1.abs(), "{curvature:?}: U {u1:e} → {u2:e}");
            let (mut f1, mut f2) = (vec![0.0; n], vec![0.0; n]);
            m.residual_inplace(0.0, &q, &zeros, &zeros, &mut f1);
            m.residual_inplace(0.0, &q2, &zeros, &zeros, &mut f2);
            let scale = amax(&f1).max(1e-6);
            for blk in (0..n).step_by(3) {
                let d = (rm * vec_of(&f1, blk) - vec_of(&f2, blk)).norm();
                prop_assert!(d < 1e-9 * scale, "{curvature:?}: block {blk}: {d:e} (scale {scale:e})");
            }
        }
    }
}
