//! Property tests (proptest) of the velocity-level flared hinge (SHARPy-style `hinge_node_FoR`,
//! angular rows projected on the fixed pair `z, a_B × z` ⟂ a_B), of the rotation algebra it
//! rests on (CRV, quaternions, tangential operator, rescaling past π) and of the objectivity
//! of the elastic force, over random geometry and random (flexible) states.
//!
//! Inputs are plain numbers and angles so that a shrunk counterexample reads directly: a
//! rotation is its rotation vector `[x, y, z]` (rad); high-dimensional filler (the nodes the
//! hinge does not see) comes from a `seed` through a fixed generator.

use gebf::crv::{BranchMap, rescale, rescale_accelerations, rescale_rates, rotation_matrix, skew, tangent};
use gebf::crv::{from_rotation_matrix, tangent_inverse};
use gebf::quaternion::Quaternion;
use gebf::{BodySpec, JointSpec, Model, Options, RigidPose, samples};
use genalpha::{ConstrainedSystem, DenseMatrix};
use nalgebra::{DMatrix, Matrix3, Rotation3, Unit, Vector3};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

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

/// A unit direction from three numbers (re-drawn when too short to normalise).
fn direction() -> impl Strategy<Value = [f64; 3]> {
    vec3().prop_filter("direction needs a non-zero vector", |v| V3::from(*v).norm() > 0.1)
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

fn get3(x: &[f64], i: usize) -> V3 {
    V3::new(x[i], x[i + 1], x[i + 2])
}

fn set3(x: &mut [f64], i: usize, v: &V3) {
    x[i..i + 3].copy_from_slice(v.as_slice());
}

fn amax(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, y| m.max(y.abs()))
}

/// Two bodies joined only by the flared hinge (joint 0): body 1 from the origin with frame
/// `rot(frame)`, body 2 from its end with the frame turned further by `rot(kink)`.
fn free_pair(beta: f64, frame: [f64; 3], kink: [f64; 3], lengths: (f64, f64), n_el: (usize, usize)) -> Model {
    let fp = rot(frame);
    let fc = fp * rot(kink);
    let body = |name: &str, start, length, frame, n_elements| BodySpec {
        name: name.into(),
        start,
        length,
        frame,
        section: samples::paper_section(1.0),
        n_elements,
        point_masses: Vec::new(),
        twist: gebf::Twist::none(),
    };
    let bodies =
        vec![body("p", V3::zeros(), lengths.0, fp, n_el.0), body("c", fp.column(0) * lengths.0, lengths.1, fc, n_el.1)];
    let joints = [JointSpec::FlaredHinge { parent: 0, child: 1, beta }];
    Model::new(&bodies, &joints, V3::zeros(), Options::default()).expect("valid scene")
}

/// A flexible state of the free pair and what it was built from.
struct Hinged {
    q: Vec<f64>,
    v: Vec<f64>,
    /// Hinge axis a (global).
    axis: V3,
    /// C^{GAc}.
    c_child: M3,
}

/// Parent frame at `r_p` with orientation `rot(chi_p)`, velocities `v_p`, `w_p` (A components);
/// its end node at its reference place plus `dr_n` (A), with CRV `psi_n` and rates
/// `rd_n`, `psid_n`; every other parent node filled from `seed`. The child frame sits at the end
/// node, turned by the fold angle θ about the hinge axis relative to the end section, and
/// spins relative to it at `w_rel` about the axis (so the hinge rows must vanish).
#[allow(clippy::too_many_arguments)] // plain numbers on purpose: readable counterexamples
fn hinged_state(
    m: &Model,
    beta: f64,
    frame: [f64; 3],
    kink: [f64; 3],
    (r_p, chi_p, v_p, w_p): ([f64; 3], [f64; 3], [f64; 3], [f64; 3]),
    (dr_n, psi_n, rd_n, psid_n): ([f64; 3], [f64; 3], [f64; 3], [f64; 3]),
    theta: f64,
    w_rel: f64,
    seed: u64,
) -> Hinged {
    let mut s = m.initial_state();
    let (q, v) = (&mut s.q, &mut s.v);
    let last = m.n_nodes(0) - 1;
    // Filler on the parent's other nodes (small deformation and rates).
    let fill = noise(seed, 12 * last);
    for node in 1..last {
        let (ic, id) =
            (m.node_coordinate_index(0, node).unwrap().unwrap(), m.node_dof_index(0, node).unwrap().unwrap());
        for k in 0..6 {
            q[ic + k] += 0.05 * fill[12 * node + k];
            v[id + k] = fill[12 * node + 6 + k];
        }
    }
    let (fp, fd) = (m.frame_coordinate_index(0).unwrap(), m.frame_dof_index(0).unwrap());
    let cp = rot(chi_p);
    set3(q, fp, &V3::from(r_p));
    Quaternion::from_rotation_matrix(&cp).write_to(&mut q[fp + 3..fp + 7]);
    set3(v, fd, &V3::from(v_p));
    set3(v, fd + 3, &V3::from(w_p));
    let (nc, nd) = (m.node_coordinate_index(0, last).unwrap().unwrap(), m.node_dof_index(0, last).unwrap().unwrap());
    let r_n = get3(q, nc) + V3::from(dr_n) * 0.1;
    let psi_n = V3::from(psi_n);
    set3(q, nc, &r_n);
    set3(q, nc + 3, &psi_n);
    set3(v, nd, &V3::from(rd_n));
    set3(v, nd + 3, &V3::from(psid_n));

    // Child frame: C^{GAc} = C^{GBn} Rot(−a_B, θ) C^{BnAc}_0, C^{GBn} = C^{GAp} C(psi_n).
    let c_gbn = cp * rotation_matrix(&psi_n);
    let a_b = V3::new(beta.sin(), beta.cos(), 0.0);
    let rel0 = rot(frame).transpose() * (rot(frame) * rot(kink));
    let c_child = c_gbn * axis_angle(&(-a_b), theta) * rel0;
    let axis = c_gbn * a_b;
    let (fcq, fcd) = (m.frame_coordinate_index(1).unwrap(), m.frame_dof_index(1).unwrap());
    set3(q, fcq, &(V3::from(r_p) + cp * r_n));
    Quaternion::from_rotation_matrix(&c_child).write_to(&mut q[fcq + 3..fcq + 7]);
    // Hinge-point velocity and the end section's angular velocity, global.
    let vel_n = cp * (V3::from(v_p) + V3::from(rd_n) + V3::from(w_p).cross(&r_n));
    let w_n = cp * (V3::from(w_p) + rotation_matrix(&psi_n) * (tangent(&psi_n) * V3::from(psid_n)));
    let w_c = w_n + axis * w_rel;
    set3(v, fcd, &(c_child.transpose() * vel_n));
    set3(v, fcd + 3, &(c_child.transpose() * w_c));
    Hinged { q: s.q, v: s.v, axis, c_child }
}

fn psi(m: &Model, q: &[f64], v: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; m.n_velocity_constraints()];
    m.psi_inplace(0.0, q, v, &mut out);
    out
}

fn dense(d: &DenseMatrix) -> DMatrix<f64> {
    DMatrix::from_fn(d.n_rows(), d.n_cols(), |r, c| d.get(r, c))
}

/// Strategy for the parent frame's pose and velocities.
fn frame_state() -> impl Strategy<Value = ([f64; 3], [f64; 3], [f64; 3], [f64; 3])> {
    (vec3(), rotvec(), vec3(), vec3())
}

/// Strategy for the parent end node's offset, CRV (norm up to ~3.5 rad) and rates.
fn node_state() -> impl Strategy<Value = ([f64; 3], [f64; 3], [f64; 3], [f64; 3])> {
    (vec3(), rotvec(), vec3(), vec3())
}

proptest! {
    #![proptest_config(config())]

    /// With the child frame on the parent's end node, turned by any fold angle and spinning
    /// relative to the end section about the hinge axis only, the five velocity rows vanish for
    /// any flare angle, frame orientations, nodal CRV and rates; the position-level residual is
    /// zero, the fold sensor reads θ and the nodal sensors see the relative spin along a.
    #[test]
    fn hinge_motion_satisfies_the_velocity_constraints(
        beta in beta(), frame in rotvec(), kink in prop::array::uniform3(-0.8..0.8f64), n1 in 1..=3usize,
        parent in frame_state(), node in node_state(), theta in -3.0..3.0f64, w_rel in -5.0..5.0f64,
        seed in any::<u64>(),
    ) {
        let m = free_pair(beta, frame, kink, (0.6, 0.4), (n1, 1));
        let h = hinged_state(&m, beta, frame, kink, parent, node, theta, w_rel, seed);
        let p = psi(&m, &h.q, &h.v);
        prop_assert!(amax(&p) < 1e-13, "Ψ = {p:?}");
        prop_assert!(m.constraint_residual(&h.q) < 1e-13, "residual {:e}", m.constraint_residual(&h.q));
        let fold = m.fold_angle(&h.q, 0).unwrap();
        prop_assert!((fold - theta).abs() < 1e-13, "fold {fold} vs θ {theta}");
        let last = m.n_nodes(0) - 1;
        let w_n = m.node_angular_velocity(&h.q, &h.v, 0, last).unwrap();
        let w_c = m.node_angular_velocity(&h.q, &h.v, 1, 0).unwrap();
        prop_assert!((w_c - w_n - h.axis * w_rel).norm() < 1e-12 * (1.0 + w_c.norm()));
        let gap = m.node_velocity(&h.q, &h.v, 0, last).unwrap() - m.node_velocity(&h.q, &h.v, 1, 0).unwrap();
        prop_assert!(gap.norm() < 1e-12 * (1.0 + w_c.norm()));
    }

    /// A relative angular velocity δω and a relative linear velocity δv of the child at the
    /// hinge violate the rows in proportion: |Ψ_lin| = |δv| and |Ψ_rot| = |δω − (δω·a)a|
    /// exactly (the projection pair is orthonormal and ⟂ a); δω along a is free.
    #[test]
    fn off_axis_relative_motion_violates_in_proportion(
        beta in beta(), frame in rotvec(), kink in prop::array::uniform3(-0.8..0.8f64),
        parent in frame_state(), node in node_state(), theta in -3.0..3.0f64, w_rel in -5.0..5.0f64,
        dw in vec3(), dv in vec3(),
    ) {
        let m = free_pair(beta, frame, kink, (0.6, 0.4), (2, 1));
        let mut h = hinged_state(&m, beta, frame, kink, parent, node, theta, w_rel, 7);
        let (dw, dv) = (V3::from(dw), V3::from(dv));
        let fcd = m.frame_dof_index(1).unwrap();
        let vc = get3(&h.v, fcd) + h.c_child.transpose() * dv;
        let wc = get3(&h.v, fcd + 3) + h.c_child.transpose() * dw;
        set3(&mut h.v, fcd, &vc);
        set3(&mut h.v, fcd + 3, &wc);
        let p = psi(&m, &h.q, &h.v);
        let lin = V3::new(p[0], p[1], p[2]).norm();
        let ang = (p[3] * p[3] + p[4] * p[4]).sqrt();
        let perp = (dw - h.axis * dw.dot(&h.axis)).norm();
        prop_assert!((lin - dv.norm()).abs() < 1e-13, "|Ψ_lin| = {lin} vs |δv| = {}", dv.norm());
        prop_assert!((ang - perp).abs() < 1e-13, "|Ψ_rot| = {ang} vs |δω⊥| = {perp}");
    }

    /// The constraint Jacobians equal finite differences at random flexible states with random
    /// (inconsistent) velocities: B = ∂Ψ/∂v, ∂(B v)/∂q and ∂(Bᵀ μ)/∂q, the q-derivatives along
    /// the model's retraction (additive on nodes, `χ ⊗ exp(δθ/2)` on frames).
    #[test]
    fn constraint_jacobians_equal_finite_differences(
        beta in beta(), frame in rotvec(), kink in prop::array::uniform3(-0.8..0.8f64),
        parent in frame_state(), node in node_state(), theta in -3.0..3.0f64, seed in any::<u64>(),
    ) {
        let m = free_pair(beta, frame, kink, (0.6, 0.4), (1, 1));
        let h = hinged_state(&m, beta, frame, kink, parent, node, theta, 0.0, seed);
        let (n, nr) = (m.n_dof(), m.n_velocity_constraints());
        let v: Vec<f64> = noise(seed ^ 1, n);
        let mu: Vec<f64> = noise(seed ^ 2, nr);
        let mut b = DenseMatrix::zeros(nr, n);
        m.psi_v_inplace(0.0, &h.q, &mut b.view());
        let b = dense(&b);
        let bv = &b * DMatrix::from_column_slice(n, 1, &v);
        let err = (bv - DMatrix::from_column_slice(nr, 1, &psi(&m, &h.q, &v))).amax();
        prop_assert!(err < 1e-13, "B v ≠ Ψ: {err:e}");
        let mut jq = DenseMatrix::zeros(nr, n);
        m.psi_q_inplace(0.0, &h.q, &v, &mut jq.view());
        let jq = dense(&jq);
        let mut kf = DenseMatrix::zeros(n, n);
        m.constraint_force_tangent_inplace(0.0, &h.q, &[], &mu, 1.0, &mut kf.view());
        let kf = dense(&kf);
        let force = |q: &[f64]| {
            let mut b = DenseMatrix::zeros(nr, n);
            m.psi_v_inplace(0.0, q, &mut b.view());
            dense(&b).transpose() * DMatrix::from_column_slice(nr, 1, &mu)
        };
        let step = 1e-6;
        let (mut fd_psi, mut fd_force) = (DMatrix::zeros(nr, n), DMatrix::zeros(n, n));
        let (mut qp, mut qm) = (h.q.clone(), h.q.clone());
        for c in 0..n {
            let mut dq = vec![0.0; n];
            dq[c] = step;
            m.retract_inplace(&h.q, &dq, &mut qp);
            dq[c] = -step;
            m.retract_inplace(&h.q, &dq, &mut qm);
            let (pp, pm) = (psi(&m, &qp, &v), psi(&m, &qm, &v));
            for r in 0..nr {
                fd_psi[(r, c)] = (pp[r] - pm[r]) / (2.0 * step);
            }
            fd_force.set_column(c, &((force(&qp) - force(&qm)) / (2.0 * step)).column(0));
        }
        let rel = |a: &DMatrix<f64>, b: &DMatrix<f64>| (a - b).amax() / b.amax().max(1.0);
        prop_assert!(rel(&jq, &fd_psi) < 1e-8, "∂(B v)/∂q: {:e}", rel(&jq, &fd_psi));
        prop_assert!(rel(&kf, &fd_force) < 1e-8, "∂(Bᵀ μ)/∂q: {:e}", rel(&kf, &fd_force));
    }

    /// CRV ↔ rotation matrix ↔ quaternion round trips (|ψ| < π), orthonormality, and the
    /// quaternion's matrix equals the CRV's.
    #[test]
    fn crv_matrix_quaternion_round_trips(axis in direction(), angle in 0.0..3.1f64) {
        let psi = V3::from(axis).normalize() * angle;
        let c = rotation_matrix(&psi);
        prop_assert!((c.transpose() * c - M3::identity()).amax() < 1e-14);
        prop_assert!((c.determinant() - 1.0).abs() < 1e-14);
        let q = Quaternion::from_rotation_vector(&psi);
        prop_assert!((q.to_rotation_matrix() - c).amax() < 1e-14);
        prop_assert!((q.to_crv() - psi).norm() < 1e-14, "quaternion → CRV {} vs {psi}", q.to_crv());
        // The logarithm loses digits as the angle nears π (the axis comes from C − Cᵀ ∝ sin φ).
        let tol = 1e-14 / (PI - angle);
        prop_assert!((from_rotation_matrix(&c) - psi).norm() < tol, "matrix → CRV {}", from_rotation_matrix(&c));
        let qc = Quaternion::from_rotation_matrix(&c);
        prop_assert!((qc.w - q.w).abs() < 1e-14 && (qc.v - q.v).norm() < 1e-14, "{qc:?} vs {q:?}");
        prop_assert!((qc.to_rotation_matrix() - c).amax() < 1e-14);
    }

    /// Composition: `C(χ₁ ⊗ χ₂) = C(χ₁) C(χ₂)`, the conjugate is the transpose, `rotate` is the
    /// matrix product, and the Lie update `χ ⊗ exp(δθ/2)` is `C exp(δθ̃)`.
    #[test]
    fn quaternion_composition_follows_the_matrices(a in rotvec(), b in rotvec(), x in vec3(), dth in rotvec()) {
        let (qa, qb) = (Quaternion::from_rotation_vector(&V3::from(a)), Quaternion::from_rotation_vector(&V3::from(b)));
        let (ca, cb) = (rot(a), rot(b));
        prop_assert!((qa.mul(&qb).to_rotation_matrix() - ca * cb).amax() < 1e-14);
        prop_assert!((qa.conjugate().to_rotation_matrix() - ca.transpose()).amax() < 1e-14);
        prop_assert!((qa.rotate(&V3::from(x)) - ca * V3::from(x)).norm() < 1e-14);
        let r = qa.retract(&V3::from(dth));
        prop_assert!((r.to_rotation_matrix() - ca * rotation_matrix(&V3::from(dth))).amax() < 1e-14);
        prop_assert!((r.norm() - 1.0).abs() < 1e-14);
        // and CRVs compose through their matrices
        let c = from_rotation_matrix(&(ca * cb));
        prop_assert!((rotation_matrix(&c) - ca * cb).amax() < 1e-13);
    }

    /// `Ω = T(ψ) ψ̇` is the section angular velocity: `skew(Ω) = Cᵀ Ċ` with `Ċ` by central
    /// differences along `ψ + t ψ̇`; `T⁻¹ T = I` (|ψ| < 2π).
    #[test]
    fn tangential_operator_gives_the_angular_velocity(axis in direction(), angle in 0.0..5.5f64, psi_dot in vec3()) {
        let psi = V3::from(axis).normalize() * angle;
        let pd = V3::from(psi_dot);
        let h = 1e-5;
        let c_dot = (rotation_matrix(&(psi + pd * h)) - rotation_matrix(&(psi - pd * h))) / (2.0 * h);
        let w_fd = rotation_matrix(&psi).transpose() * c_dot;
        let w = tangent(&psi) * pd;
        prop_assert!((w_fd - skew(&w)).amax() < 1e-9, "T ψ̇ = {w} vs FD {w_fd}");
        prop_assert!((tangent_inverse(&psi) * tangent(&psi) - M3::identity()).amax() < 1e-13 / (2.0 * PI - angle));
    }

    /// Rescaling across |ψ| = π: `rescale` returns None below π; above, a CRV of norm ≤ π with
    /// the same rotation, and the transformed rates give the same angular velocity and angular
    /// acceleration (compared through finite differences of the rotation matrices, not through
    /// T). The branch maps `ψ (1 + 2πj/|ψ|)` keep the rotation too.
    #[test]
    fn rescaling_keeps_rotation_and_angular_velocity(
        axis in direction(), angle in (PI - 0.5)..(3.0 * PI - 0.5), psi_dot in vec3(), psi_ddot in vec3(),
        j in -2..=2i32,
    ) {
        let psi = V3::from(axis).normalize() * angle;
        let (pd, pdd) = (V3::from(psi_dot), V3::from(psi_ddot));
        let Some(new) = rescale(&psi) else {
            prop_assert!(angle <= PI, "no rescale at |ψ| = {angle}");
            return Ok(());
        };
        prop_assert!(angle > PI);
        prop_assert!(new.norm() <= PI + 1e-12, "|ψ_new| = {}", new.norm());
        prop_assert!((rotation_matrix(&new) - rotation_matrix(&psi)).amax() < 1e-13);
        let pd_new = rescale_rates(&psi, &new, &pd);
        let pdd_new = rescale_accelerations(&psi, &new, &pd, &pd_new, &pdd);
        // Paths ψ(t) = ψ + t ψ̇ + ½t² ψ̈ in both parametrisations: same C(t) to second order.
        let path = |p: &V3, d: &V3, dd: &V3, t: f64| rotation_matrix(&(p + d * t + dd * (0.5 * t * t)));
        let h = 1e-4;
        let first = |p, d, dd| (path(p, d, dd, h) - path(p, d, dd, -h)) / (2.0 * h);
        let second = |p, d, dd| (path(p, d, dd, h) - path(p, d, dd, 0.0) * 2.0 + path(p, d, dd, -h)) / (h * h);
        let (d_old, d_new) = (first(&psi, &pd, &pdd), first(&new, &pd_new, &pdd_new));
        let scale = 1.0 + pd.norm();
        prop_assert!((d_old - d_new).amax() < 1e-8 * scale * scale, "Ċ {d_old} vs {d_new}");
        let (dd_old, dd_new) = (second(&psi, &pd, &pdd), second(&new, &pd_new, &pdd_new));
        prop_assert!((dd_old - dd_new).amax() < 1e-6 * scale.powi(3), "C̈ {dd_old} vs {dd_new}");
        if j != 0 {
            let b = BranchMap::new(&psi, j);
            prop_assert!((rotation_matrix(&b.apply()) - rotation_matrix(&psi)).amax() < 1e-12);
        }
    }

    /// Objectivity: random rigid motions of the bodies (random frame rotations and positions,
    /// joints not enforced; node 0 is clamped to its frame, so the frame carries every rigid
    /// motion of a body) leave the elastic energy and the elastic force at zero (zero rates, no
    /// gravity). A deformed body keeps its elastic energy and nodal elastic forces (A
    /// components) under any superposed rigid motion of its frame.
    #[test]
    fn rigid_motions_have_zero_elastic_energy_and_force(
        r1 in rotvec(), t1 in vec3(), r2 in rotvec(), t2 in vec3(), n_el in 1..=4usize, c in 0.01..1.0f64,
        seed in any::<u64>(), amplitude in 0.0..0.05f64,
    ) {
        let (b, j, _) = samples::double_pendulum(c, 30.0, n_el);
        let m = Model::new(&b, &j, V3::zeros(), Options::default()).unwrap();
        let still = |r, t| RigidPose { rotation: rot(r), translation: V3::from(t), ..RigidPose::at_rest(V3::zeros()) };
        let s = m.rigid_state(&[still(r1, t1), still(r2, t2)]).unwrap();
        let n = m.n_dof();
        let zeros = vec![0.0; n];
        let mut f = vec![0.0; n];
        m.residual_inplace(0.0, &s.q, &zeros, &zeros, &mut f);
        let ea = b[0].section.ea;
        prop_assert!(amax(&f) < 1e-12 * ea, "|f_el| = {:e} N (EA = {ea:e})", amax(&f));
        let u = m.energies(&s.q, &zeros).elastic;
        prop_assert!(u.abs() < 1e-26 * ea, "U = {u:e} J");

        // Deformed nodes (same in both), frames at rest and moved.
        let mut deformed = m.initial_state().q;
        let fill = noise(seed, deformed.len());
        for body in 0..2 {
            for node in 1..m.n_nodes(body) {
                let i = m.node_coordinate_index(body, node).unwrap().unwrap();
                for k in 0..6 {
                    deformed[i + k] += amplitude * fill[i + k];
                }
            }
        }
        let mut moved = deformed.clone();
        for body in 0..2 {
            let fc = m.frame_coordinate_index(body).unwrap();
            moved[fc..fc + 7].copy_from_slice(&s.q[fc..fc + 7]);
        }
        let (mut f0, mut f1) = (vec![0.0; n], vec![0.0; n]);
        m.residual_inplace(0.0, &deformed, &zeros, &zeros, &mut f0);
        m.residual_inplace(0.0, &moved, &zeros, &zeros, &mut f1);
        let (u0, u1) = (m.energies(&deformed, &zeros).elastic, m.energies(&moved, &zeros).elastic);
        prop_assert!(amplitude == 0.0 || u0 > 0.0);
        prop_assert!((u0 - u1).abs() <= 1e-13 * u0, "U {u0:e} → {u1:e}");
        let err = f0.iter().zip(&f1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        prop_assert!(err <= 1e-13 * amax(&f0), "elastic forces change by {err:e} (scale {:e})", amax(&f0));
    }
}
