//! Every analytic tangent against central finite differences of its residual at random states.
//!
//! Element level: the inertial forces (mass, gyroscopic and inertial-stiffness parts), the
//! elastic forces and gravity, each on its own so that no term hides behind a larger one.
//! Model level: the full iteration matrix (including nodal loads), the joint Jacobian `B`,
//! `∂(B v)/∂q` and `∂(Bᵀ mu)/∂q`, all derivatives with respect to `q` taken along the model's
//! retraction. Tolerance: relative error below 1e-6 (max-norm of the difference over the
//! max-norm of the matrix).

use crate::crv::{M3, V3, rotation_matrix};
use crate::element::{ElementState, Mat24, Vec24};
use crate::gravity::add_gravity;
use crate::inertia::{MatrixCoefficients, add_inertia};
use crate::rigid_slice::{Slice, add_slice_gravity, add_slice_inertia};
use crate::stiffness::add_elastic;
use crate::{BodySpec, ForceElement, JointSpec, Model, NodalLoad, Options, PointMass, Scene, Section};
use genalpha::{ConstrainedSystem, DenseMatrix};
use proptest::prelude::*;

const H: f64 = 1e-6;
const TOL: f64 = 1e-6;

/// A section with all properties of order one, so that every term of the tangent matters.
fn unit_section() -> Section {
    Section {
        mass: 1.3,
        rho_ixx: 0.5,
        rho_iyy: 0.2,
        rho_izz: 0.35,
        ea: 7.0,
        ga_y: 3.0,
        ga_z: 4.0,
        gj: 1.5,
        ei_yy: 2.0,
        ei_zz: 2.5,
        cg_offset: [0.0; 2],
    }
}

fn rel_err(a: &Mat24, b: &Mat24) -> f64 {
    (a - b).amax() / a.amax().max(1e-300)
}

/// A deterministic pseudo-random generator (tests must be reproducible).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    fn v3(&mut self, s: f64) -> V3 {
        V3::new(self.next() * s, self.next() * s, self.next() * s)
    }
}

fn random_state(rng: &mut Lcg, le: f64, rot: f64) -> ElementState {
    let mut s = ElementState::default();
    for k in 0..3 {
        s.r[k] = V3::new(0.3 + 0.5 * le * k as f64, 0.0, 0.0) + rng.v3(0.1);
        s.psi[k] = rng.v3(rot);
        s.rd[k] = rng.v3(1.0);
        s.psid[k] = rng.v3(1.0);
        s.rdd[k] = rng.v3(1.0);
        s.psidd[k] = rng.v3(1.0);
    }
    s.v = rng.v3(1.0);
    s.w = rng.v3(1.0);
    s.vd = rng.v3(1.0);
    s.wd = rng.v3(1.0);
    s
}

#[derive(Clone, Copy)]
enum Slot {
    Q,
    V,
    A,
}

/// The field of `s` that local unknown block `blk` of `slot` lives in (None: frame position,
/// or frame rotation in the `q` slot, which only acts through `g_a`).
fn field(s: &mut ElementState, slot: Slot, blk: usize) -> Option<&mut V3> {
    match (slot, blk) {
        (Slot::Q, b) if b < 6 => Some(if b % 2 == 0 { &mut s.r[b / 2] } else { &mut s.psi[b / 2] }),
        (Slot::V, b) if b < 6 => Some(if b % 2 == 0 { &mut s.rd[b / 2] } else { &mut s.psid[b / 2] }),
        (Slot::A, b) if b < 6 => Some(if b % 2 == 0 { &mut s.rdd[b / 2] } else { &mut s.psidd[b / 2] }),
        (Slot::V, 6) => Some(&mut s.v),
        (Slot::V, 7) => Some(&mut s.w),
        (Slot::A, 6) => Some(&mut s.vd),
        (Slot::A, 7) => Some(&mut s.wd),
        _ => None,
    }
}

/// Perturb local unknown `j` of the given slot by `h`; for `q`, frame rotations rotate `g_a`
/// (C^{AG} ← exp(−δθ̃) C^{AG}) and frame translations change nothing.
fn perturbed(st: &ElementState, g_a: &V3, slot: Slot, j: usize, h: f64) -> (ElementState, V3) {
    let mut s = *st;
    let mut g = *g_a;
    let (blk, c) = (j / 3, j % 3);
    if let Some(x) = field(&mut s, slot, blk) {
        x[c] += h;
    } else if let (Slot::Q, 7) = (slot, blk) {
        g = rotation_matrix(&(-V3::ith(c, h))) * g;
    }
    (s, g)
}

fn fd_matrix(f: impl Fn(&ElementState, &V3) -> Vec24, st: &ElementState, g_a: &V3, slot: Slot) -> Mat24 {
    let mut m = Mat24::zeros();
    for j in 0..24 {
        let (sp, gp) = perturbed(st, g_a, slot, j, H);
        let (sm, gm) = perturbed(st, g_a, slot, j, -H);
        m.set_column(j, &((f(&sp, &gp) - f(&sm, &gm)) / (2.0 * H)));
    }
    m
}

fn check_element(seed: u64, rot: f64) {
    let mut rng = Lcg(seed);
    let le = 0.8;
    let sec = unit_section();
    let st = random_state(&mut rng, le, rot);
    let g_a = rng.v3(2.0);
    let inertia = |s: &ElementState, _g: &V3| {
        let mut r = Vec24::zeros();
        add_inertia(s, le, &sec, &mut r, None);
        r
    };
    let elastic = |s: &ElementState, _g: &V3| {
        let mut r = Vec24::zeros();
        add_elastic(s, le, &sec, 2, None, &mut r, None);
        r
    };
    let gravity = |s: &ElementState, g: &V3| {
        let mut r = Vec24::zeros();
        add_gravity(s, le, sec.mass, g, &mut r, None);
        r
    };
    for (slot, c) in [(Slot::A, [1.0, 0.0, 0.0]), (Slot::V, [0.0, 1.0, 0.0]), (Slot::Q, [0.0, 0.0, 1.0])] {
        let mut an = Mat24::zeros();
        let mut r = Vec24::zeros();
        let coeffs = MatrixCoefficients { c_m: c[0], c_c: c[1], c_k: c[2] };
        add_inertia(&st, le, &sec, &mut r, Some((&mut an, coeffs)));
        let fd = fd_matrix(inertia, &st, &g_a, slot);
        let e = rel_err(&an, &fd);
        assert!(
            e < TOL,
            "inertia tangent (seed {seed}, slot {}) rel err {e:.2e}",
            c.iter().position(|x| *x == 1.0).unwrap()
        );
    }
    let mut an = Mat24::zeros();
    let mut r = Vec24::zeros();
    add_elastic(&st, le, &sec, 2, None, &mut r, Some((&mut an, 1.0)));
    let e = rel_err(&an, &fd_matrix(elastic, &st, &g_a, Slot::Q));
    println!("seed {seed}: elastic rel err {e:.2e}");
    assert!(e < TOL, "elastic tangent (seed {seed}) rel err {e:.2e}");
    assert!((an - an.transpose()).amax() < 1e-9 * an.amax(), "elastic tangent not symmetric");
    let mut an = Mat24::zeros();
    add_gravity(&st, le, sec.mass, &g_a, &mut r, Some((&mut an, 1.0)));
    let e = rel_err(&an, &fd_matrix(gravity, &st, &g_a, Slot::Q));
    println!("seed {seed}: gravity rel err {e:.2e}");
    assert!(e < TOL, "gravity tangent (seed {seed}) rel err {e:.2e}");
}

/// A rigid slice with an offset centre (a point mass, or a section with its centre of mass off
/// the axis): inertia tangents (each coefficient) and gravity tangents, with and without the
/// axis part, against finite differences.
fn check_slice(seed: u64, rot: f64) {
    let mut rng = Lcg(seed);
    let le = 0.8;
    let st = random_state(&mut rng, le, rot);
    let g_a = rng.v3(2.0);
    let slice = Slice { xi: rng.next(), mass: 1.7, inertia: V3::new(0.3, 0.2, 0.25), offset: rng.v3(0.4) };
    let wt = 0.37;
    let inertia = |s: &ElementState, _g: &V3| {
        let mut r = Vec24::zeros();
        add_slice_inertia(s, le, wt, &slice, &mut r, None);
        r
    };
    for (slot, c) in [(Slot::A, [1.0, 0.0, 0.0]), (Slot::V, [0.0, 1.0, 0.0]), (Slot::Q, [0.0, 0.0, 1.0])] {
        let mut an = Mat24::zeros();
        let mut r = Vec24::zeros();
        let coeffs = MatrixCoefficients { c_m: c[0], c_c: c[1], c_k: c[2] };
        add_slice_inertia(&st, le, wt, &slice, &mut r, Some((&mut an, coeffs)));
        let e = rel_err(&an, &fd_matrix(inertia, &st, &g_a, slot));
        println!("seed {seed}: slice inertia slot {:?} rel err {e:.2e}", c);
        assert!(e < TOL, "slice inertia tangent (seed {seed}, {c:?}) rel err {e:.2e}");
    }
    for axis_part in [true, false] {
        let gravity = |s: &ElementState, g: &V3| {
            let mut r = Vec24::zeros();
            add_slice_gravity(s, le, wt, &slice, g, axis_part, &mut r, None);
            r
        };
        let mut an = Mat24::zeros();
        let mut r = Vec24::zeros();
        add_slice_gravity(&st, le, wt, &slice, &g_a, axis_part, &mut r, Some((&mut an, 1.0)));
        let e = rel_err(&an, &fd_matrix(gravity, &st, &g_a, Slot::Q));
        println!("seed {seed}: slice gravity (axis part {axis_part}) rel err {e:.2e}");
        assert!(e < TOL, "slice gravity tangent (seed {seed}, axis part {axis_part}) rel err {e:.2e}");
    }
}

#[test]
fn slice_tangents_match_finite_differences() {
    for seed in 31..36 {
        check_slice(seed, 0.6);
    }
    check_slice(41, 1e-7);
    check_slice(43, 1.5);
}

/// With a zero offset the slice kernel at the three Gauss points is the axis kernel (same
/// forces, matrices and kinetic energy to round-off).
#[test]
fn slice_kernel_without_offset_is_the_axis_kernel() {
    let mut rng = Lcg(57);
    let (le, sec) = (0.8, unit_section());
    let st = random_state(&mut rng, le, 0.7);
    let c = MatrixCoefficients { c_m: 0.9, c_c: 0.4, c_k: 0.3 };
    let (mut r1, mut r2, mut m1, mut m2) = (Vec24::zeros(), Vec24::zeros(), Mat24::zeros(), Mat24::zeros());
    let t1 = add_inertia(&st, le, &sec, &mut r1, Some((&mut m1, c)));
    let mut t2 = 0.0;
    for &(xi, w) in crate::element::gauss_rule(3) {
        let s =
            Slice { xi, mass: sec.mass, inertia: V3::new(sec.rho_ixx, sec.rho_iyy, sec.rho_izz), offset: V3::zeros() };
        t2 += add_slice_inertia(&st, le, 0.5 * le * w, &s, &mut r2, Some((&mut m2, c)));
    }
    assert!((t1 - t2).abs() < 1e-13 * t1.abs());
    assert!((r1 - r2).amax() < 1e-13 * r1.amax());
    assert!(rel_err(&m1, &m2) < 1e-13);
}

#[test]
fn element_tangents_match_finite_differences() {
    for seed in 1..6 {
        check_element(seed, 0.6);
    }
}

#[test]
fn element_tangents_near_zero_rotation() {
    check_element(11, 1e-7);
}

#[test]
fn element_tangents_at_large_rotation() {
    // Nodal CRVs up to ~2.6 rad, i.e. close to π.
    check_element(23, 1.5);
}

#[test]
fn mass_matrix_is_symmetric_positive_definite() {
    let mut rng = Lcg(5);
    let sec = unit_section();
    let st = random_state(&mut rng, 0.8, 0.8);
    let mut m = Mat24::zeros();
    let mut r = Vec24::zeros();
    add_inertia(&st, 0.8, &sec, &mut r, Some((&mut m, MatrixCoefficients { c_m: 1.0, c_c: 0.0, c_k: 0.0 })));
    assert!((m - m.transpose()).amax() < 1e-13 * m.amax());
    // The element alone with its frame: 24 unknowns, 3 nodes × 6 + 6 frame dofs — the frame
    // motion duplicates a rigid motion of the nodes, so M is positive semi-definite with a
    // 6-dimensional null space; check v̇ᵀ M v̇ ≥ 0 on random vectors.
    for _ in 0..20 {
        let x = nalgebra::SVector::<f64, 24>::from_fn(|_, _| rng.next());
        assert!(x.dot(&(m * x)) >= -1e-12);
    }
}

/// A two-body flared pendulum with a third free body hanging off the second: covers the ground
/// hinge, two flared hinges and nodal loads at a random state.
/// Optionally with a hinge spring and damper on every free hinge.
fn random_model_with(
    rng: &mut Lcg,
    beta: f64,
    locked: bool,
    springs: bool,
) -> (Model, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    random_model_full(rng, beta, locked, springs, false)
}

/// [`random_model_with`], optionally with point masses (at a node, inside an element, at both
/// body ends) and a centre-of-mass offset on two of the bodies' sections.
fn random_model_full(
    rng: &mut Lcg,
    beta: f64,
    locked: bool,
    springs: bool,
    masses: bool,
) -> (Model, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    random_model_twisted(rng, beta, locked, springs, masses, false)
}

/// [`random_model_full`], optionally with twisted bodies (a linear twist, a table with a
/// breakpoint inside an element, a constant twist; docs/gebf.md §4).
fn random_model_twisted(
    rng: &mut Lcg,
    beta: f64,
    locked: bool,
    springs: bool,
    masses: bool,
    twisted: bool,
) -> (Model, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    random_model_forces(rng, beta, locked, springs, masses, twisted, Vec::new())
}

/// [`random_model_twisted`] with the force elements `extra` added to the scene.
fn random_model_forces(
    rng: &mut Lcg,
    beta: f64,
    locked: bool,
    springs: bool,
    masses: bool,
    twisted: bool,
    extra: Vec<ForceElement>,
) -> (Model, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let sec = unit_section();
    let f1 = rotation_matrix(&V3::new(0.1, -0.2, 0.3));
    let f2 = rotation_matrix(&V3::new(-0.3, 0.2, 0.4));
    let f3 = rotation_matrix(&V3::new(0.5, 0.1, -0.2));
    let s1 = V3::new(0.1, 0.2, -0.1);
    let s2 = s1 + f1.column(0) * 1.1;
    let s3 = s2 + f2.column(0) * 0.9;
    let body = |name: &str, start: V3, frame: M3, l: f64, n: usize| BodySpec {
        name: name.into(),
        start,
        length: l,
        frame,
        section: sec,
        n_elements: n,
        point_masses: Vec::new(),
        twist: crate::Twist::none(),
    };
    let mut bodies = vec![body("a", s1, f1, 1.1, 2), body("b", s2, f2, 0.9, 2), body("c", s3, f3, 0.7, 1)];
    if masses {
        let pm = |at: f64, offset: V3, mass: f64| PointMass { at, offset, mass, inertia: V3::new(0.05, 0.03, 0.04) };
        bodies[0].point_masses = vec![pm(0.3, V3::new(0.1, -0.2, 0.15), 0.8), pm(1.1, V3::new(0.0, 0.3, -0.1), 0.5)];
        bodies[1].section.cg_offset = [0.07, -0.05];
        bodies[1].point_masses = vec![pm(0.45, V3::new(-0.05, 0.1, 0.2), 1.2)];
        bodies[2].section.cg_offset = [-0.1, 0.04];
        bodies[2].point_masses = vec![pm(0.0, V3::new(0.05, 0.1, 0.0), 0.6), pm(0.5, V3::zeros(), 0.4)];
    }
    if twisted {
        bodies[0].twist = crate::Twist::linear(0.3, 1.4, 1.1);
        bodies[1].twist = crate::Twist::table(vec![(0.0, -0.2), (0.3, 0.5), (0.9, 0.1)]);
        bodies[2].twist = crate::Twist::table(vec![(0.2, 0.8)]);
    }
    let joints = vec![
        JointSpec::GroundHinge { body: 0, axis: V3::new(0.2, 1.0, 0.1) },
        JointSpec::FlaredHinge { parent: 0, child: 1, beta },
        if locked {
            JointSpec::LockedHinge { parent: 1, child: 2, beta: -0.3, fold: 0.0 }
        } else {
            JointSpec::FlaredHinge { parent: 1, child: 2, beta: -0.3 }
        },
    ];
    let mut scene = Scene::new(bodies, joints, V3::new(0.5, -1.0, -9.8));
    if springs {
        let free = if locked { 2 } else { 3 };
        for (joint, stiffness, damping, rest) in
            [(0, 3.0, 0.7, 0.2), (1, 2.0, 1.3, -0.4), (2, 1.5, 0.4, 2.9)].into_iter().take(free)
        {
            scene.forces.push(ForceElement::HingeSpring { joint, stiffness, damping, rest });
        }
    }
    scene.forces.extend(extra);
    let mut model = Model::from_scene(&scene, Options::default()).unwrap();
    model.set_nodal_load(1, 4, NodalLoad { force: rng.v3(2.0), moment: rng.v3(2.0) }).unwrap();
    model.set_nodal_load(2, 0, NodalLoad { force: rng.v3(2.0), moment: rng.v3(2.0) }).unwrap();
    model.set_nodal_load(0, 3, NodalLoad { force: rng.v3(2.0), moment: rng.v3(2.0) }).unwrap();
    let n = model.n_dof();
    let q0 = model.reference_coordinates();
    // Random configuration: a random tangent increment from the reference.
    let dq: Vec<f64> = (0..n).map(|_| rng.next() * 0.3).collect();
    let mut q = q0.clone();
    model.retract_inplace(&q0, &dq, &mut q);
    let v: Vec<f64> = (0..n).map(|_| rng.next()).collect();
    let a: Vec<f64> = (0..n).map(|_| rng.next()).collect();
    let mu: Vec<f64> = (0..model.n_velocity_constraints()).map(|_| rng.next() * 3.0).collect();
    (model, q, v, a, mu)
}

fn dense_rel_err(an: &DenseMatrix, fd: &DenseMatrix) -> f64 {
    let mut diff: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for j in 0..an.n_cols() {
        for i in 0..an.n_rows() {
            diff = diff.max((an.get(i, j) - fd.get(i, j)).abs());
            scale = scale.max(an.get(i, j).abs());
        }
    }
    diff / scale
}

/// Finite-difference Jacobian of `f` with respect to `q` along the retraction.
fn fd_q(model: &Model, q: &[f64], n_out: usize, f: impl Fn(&[f64], &mut [f64])) -> DenseMatrix {
    let n = model.n_dof();
    let mut m = DenseMatrix::zeros(n_out, n);
    let (mut qp, mut qm) = (q.to_vec(), q.to_vec());
    let (mut rp, mut rm) = (vec![0.0; n_out], vec![0.0; n_out]);
    let mut d = vec![0.0; n];
    for j in 0..n {
        d[j] = H;
        model.retract_inplace(q, &d, &mut qp);
        d[j] = -H;
        model.retract_inplace(q, &d, &mut qm);
        d[j] = 0.0;
        f(&qp, &mut rp);
        f(&qm, &mut rm);
        for i in 0..n_out {
            *m.get_mut(i, j) = (rp[i] - rm[i]) / (2.0 * H);
        }
    }
    m
}

fn fd_x(n_in: usize, x: &[f64], n_out: usize, f: impl Fn(&[f64], &mut [f64])) -> DenseMatrix {
    let mut m = DenseMatrix::zeros(n_out, n_in);
    let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
    let (mut rp, mut rm) = (vec![0.0; n_out], vec![0.0; n_out]);
    for j in 0..n_in {
        xp[j] += H;
        xm[j] -= H;
        f(&xp, &mut rp);
        f(&xm, &mut rm);
        xp[j] = x[j];
        xm[j] = x[j];
        for i in 0..n_out {
            *m.get_mut(i, j) = (rp[i] - rm[i]) / (2.0 * H);
        }
    }
    m
}

/// The iteration matrix against finite differences of the residual, each coefficient (c_m, c_c,
/// c_k) separately.
fn check_iteration_matrix(model: &Model, q: &[f64], v: &[f64], a: &[f64], label: &str) {
    let n = model.n_dof();
    for (which, c) in [(0, [1.0, 0.0, 0.0]), (1, [0.0, 1.0, 0.0]), (2, [0.0, 0.0, 1.0])] {
        let mut an = DenseMatrix::zeros(n, n);
        model.iteration_matrix_inplace(0.0, q, v, a, c[0], c[1], c[2], &mut an.view());
        let fd = match which {
            0 => fd_x(n, a, n, |x, r| model.residual_inplace(0.0, q, v, x, r)),
            1 => fd_x(n, v, n, |x, r| model.residual_inplace(0.0, q, x, a, r)),
            _ => fd_q(model, q, n, |x, r| model.residual_inplace(0.0, x, v, a, r)),
        };
        let e = dense_rel_err(&an, &fd);
        println!("{label} part {which}: rel err {e:.2e}");
        assert!(e < TOL, "{label} part {which}: rel err {e:.2e}");
    }
}

fn check_model(seed: u64, beta: f64, locked: bool) {
    check_model_with(seed, beta, locked, false);
}

fn check_model_with(seed: u64, beta: f64, locked: bool, springs: bool) {
    check_model_full(seed, beta, locked, springs, false);
}

fn check_model_full(seed: u64, beta: f64, locked: bool, springs: bool, masses: bool) {
    check_model_twisted(seed, beta, locked, springs, masses, false);
}

fn check_model_twisted(seed: u64, beta: f64, locked: bool, springs: bool, masses: bool, twisted: bool) {
    let mut rng = Lcg(seed);
    let (model, q, v, a, mu) = random_model_twisted(&mut rng, beta, locked, springs, masses, twisted);
    let n = model.n_dof();
    let nc = model.n_velocity_constraints();
    check_iteration_matrix(&model, &q, &v, &a, &format!("model iteration matrix (seed {seed})"));
    // B = ∂psi/∂v.
    let mut b = DenseMatrix::zeros(nc, n);
    model.psi_v_inplace(0.0, &q, &mut b.view());
    let fd = fd_x(n, &v, nc, |x, r| model.psi_inplace(0.0, &q, x, r));
    let e = dense_rel_err(&b, &fd);
    println!("B (seed {seed}): rel err {e:.2e}");
    assert!(e < TOL, "B (seed {seed}): rel err {e:.2e}");
    // psi = B v exactly (scleronomic).
    let mut psi = vec![0.0; nc];
    model.psi_inplace(0.0, &q, &v, &mut psi);
    let mut bv = vec![0.0; nc];
    b.mul_vec_inplace(&v, &mut bv);
    for (x, y) in psi.iter().zip(&bv) {
        assert!((x - y).abs() < 1e-12 * (1.0 + x.abs()));
    }
    // ∂(B v)/∂q.
    let mut an = DenseMatrix::zeros(nc, n);
    model.psi_q_inplace(0.0, &q, &v, &mut an.view());
    let fd = fd_q(&model, &q, nc, |x, r| model.psi_inplace(0.0, x, &v, r));
    let e = dense_rel_err(&an, &fd);
    println!("psi_q (seed {seed}): rel err {e:.2e}");
    assert!(e < TOL, "psi_q (seed {seed}): rel err {e:.2e}");
    // ∂(Bᵀ mu)/∂q.
    let mut an = DenseMatrix::zeros(n, n);
    model.constraint_force_tangent_inplace(0.0, &q, &[], &mu, 1.0, &mut an.view());
    let fd = fd_q(&model, &q, n, |x, r| {
        let mut bm = DenseMatrix::zeros(nc, n);
        model.psi_v_inplace(0.0, x, &mut bm.view());
        r.iter_mut().for_each(|y| *y = 0.0);
        bm.add_mul_transpose_vec_inplace(&mu, r);
    });
    let e = dense_rel_err(&an, &fd);
    println!("constraint force tangent (seed {seed}): rel err {e:.2e}");
    assert!(e < TOL, "constraint force tangent (seed {seed}): rel err {e:.2e}");
}

#[test]
fn model_tangents_match_finite_differences() {
    check_model(3, 0.7, false);
}

/// Hinge springs and dampers on the ground hinge and both flared hinges: the residual's
/// position and velocity tangents (c_k, c_c parts of the iteration matrix) against finite
/// differences along the retraction.
#[test]
fn model_tangents_with_hinge_springs() {
    check_model_with(3, 0.7, false, true);
    check_model_with(8, std::f64::consts::FRAC_PI_2, false, true);
    check_model_with(5, 0.4, true, true);
}

/// The springs' own forces and tangents, isolated: the difference of the models with and
/// without springs at the same state (so no other term hides an error), against finite
/// differences along the retraction; the velocity tangent is checked the same way.
#[test]
fn hinge_spring_tangents_alone() {
    for (seed, beta) in [(3, 0.7), (9, -1.2), (12, std::f64::consts::FRAC_PI_2)] {
        let (with, q, v, a, _) = random_model_with(&mut Lcg(seed), beta, false, true);
        let (without, ..) = random_model_with(&mut Lcg(seed), beta, false, false);
        let n = with.n_dof();
        let spring = |q: &[f64], v: &[f64], r: &mut [f64]| {
            let mut r0 = vec![0.0; n];
            with.residual_inplace(0.0, q, v, &a, r);
            without.residual_inplace(0.0, q, v, &a, &mut r0);
            r.iter_mut().zip(&r0).for_each(|(x, y)| *x -= y);
        };
        for (which, c_c, c_k) in [(1, 1.0, 0.0), (2, 0.0, 1.0)] {
            let (mut k1, mut k0) = (DenseMatrix::zeros(n, n), DenseMatrix::zeros(n, n));
            with.iteration_matrix_inplace(0.0, &q, &v, &a, 0.0, c_c, c_k, &mut k1.view());
            without.iteration_matrix_inplace(0.0, &q, &v, &a, 0.0, c_c, c_k, &mut k0.view());
            let mut an = DenseMatrix::zeros(n, n);
            for j in 0..n {
                for i in 0..n {
                    *an.get_mut(i, j) = k1.get(i, j) - k0.get(i, j);
                }
            }
            let fd = if which == 1 {
                fd_x(n, &v, n, |x, r| spring(&q, x, r))
            } else {
                fd_q(&with, &q, n, |x, r| spring(x, &v, r))
            };
            let e = dense_rel_err(&an, &fd);
            println!("spring alone (seed {seed}, part {which}): rel err {e:.2e}");
            assert!(e < TOL, "spring alone (seed {seed}, part {which}): rel err {e:.2e}");
        }
    }
}

/// Thrusts (follower forces, docs/gebf.md §16) alone: the residual of the model with thrusts
/// minus the one without, on twisted, deformed and rotated bodies, against finite differences
/// along the retraction (c_k part; a thrust does not read velocities, so the c_c part is zero).
/// The thrusts sit inside an element (quadratic weights on three nodes), at a body's tip node
/// and at a body's start (node 0, clamped to the frame). Measured: rel err ≤ 3.9e-10 (the
/// thrusts alone), ≤ 1.2e-9 (the whole matrix).
#[test]
fn thrust_tangents_alone() {
    let thrust = |body, at, d: V3, m: f64| ForceElement::Thrust {
        body,
        at,
        direction: d.normalize(),
        magnitude: scene::Schedule::constant(m),
    };
    let thrusts = vec![
        thrust(0, 0.37, V3::new(0.2, -0.5, 1.0), 3.0),
        thrust(1, 0.9, V3::new(0.0, 0.0, 1.0), 2.0),
        thrust(2, 0.0, V3::new(1.0, 0.4, -0.3), 1.5),
    ];
    for (seed, beta) in [(3, 0.7), (9, -1.2)] {
        let (with, q, v, a, _) = random_model_forces(&mut Lcg(seed), beta, false, true, false, true, thrusts.clone());
        let (without, ..) = random_model_forces(&mut Lcg(seed), beta, false, true, false, true, Vec::new());
        let n = with.n_dof();
        let part = |q: &[f64], r: &mut [f64]| {
            let mut r0 = vec![0.0; n];
            with.residual_inplace(0.0, q, &v, &a, r);
            without.residual_inplace(0.0, q, &v, &a, &mut r0);
            r.iter_mut().zip(&r0).for_each(|(x, y)| *x -= y);
        };
        let (mut k1, mut k0) = (DenseMatrix::zeros(n, n), DenseMatrix::zeros(n, n));
        with.iteration_matrix_inplace(0.0, &q, &v, &a, 0.0, 0.0, 1.0, &mut k1.view());
        without.iteration_matrix_inplace(0.0, &q, &v, &a, 0.0, 0.0, 1.0, &mut k0.view());
        let mut an = DenseMatrix::zeros(n, n);
        for j in 0..n {
            for i in 0..n {
                *an.get_mut(i, j) = k1.get(i, j) - k0.get(i, j);
            }
        }
        let fd = fd_q(&with, &q, n, part);
        let e = dense_rel_err(&an, &fd);
        let asym = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .map(|(i, j)| (an.get(i, j) - an.get(j, i)).abs())
            .fold(0.0, f64::max);
        println!("thrust alone (seed {seed}): rel err {e:.2e}, unsymmetric part {asym:.2e}");
        assert!(e < TOL, "thrust alone (seed {seed}): rel err {e:.2e}");
        assert!(asym > 1e-3, "a follower force's tangent is unsymmetric");
        // the whole model's matrix with the thrusts, every coefficient
        check_iteration_matrix(&with, &q, &v, &a, &format!("model with thrusts (seed {seed})"));
    }
}

/// Point masses (at node 0, at a middle node, inside elements, at a body's end) and offset
/// section centres of mass, with gravity, nodal loads and springs: every model tangent.
#[test]
fn model_tangents_with_point_masses_and_offsets() {
    check_model_full(4, 0.6, false, true, true);
    check_model_full(13, -0.9, true, false, true);
}

/// Twisted bodies (the reference curvature in the strain, the twisted reference CRVs and the
/// flared hinges' reference relative rotations), with point masses, offsets and springs.
#[test]
fn model_tangents_with_twisted_bodies() {
    check_model_twisted(4, 0.6, false, true, true, true);
    check_model_twisted(13, -0.9, true, false, true, true);
}

/// The locked hinge's sixth (axial) angular row in every tangent.
#[test]
fn model_tangents_with_a_locked_hinge() {
    check_model(5, 0.4, true);
}

#[test]
fn model_tangents_at_ninety_degree_flare() {
    check_model(8, std::f64::consts::FRAC_PI_2, false);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]
    #[test]
    fn element_tangents_random_states(seed in 100u64..100_000, rot in 0.0f64..1.2) {
        check_element(seed, rot);
    }
}

/// Elements whose end nodes are stored on another CRV branch than their middle node (stored
/// CRVs rescaled to |psi| ≤ π): the residual and every tangent must still be exact.
#[test]
fn model_tangents_with_rescaled_crvs() {
    rescaled_crvs(false);
}

/// The same with an offset section centre of mass and point masses (the slices take the mapped
/// element state and the chain rule of the mapped matrix like the axis kernel).
#[test]
fn model_tangents_with_rescaled_crvs_and_point_masses() {
    rescaled_crvs(true);
}

fn rescaled_crvs(masses: bool) {
    let mut rng = Lcg(77);
    let mut sec = unit_section();
    let mut point_masses = Vec::new();
    if masses {
        sec.cg_offset = [0.08, -0.06];
        let inertia = V3::new(0.05, 0.03, 0.04);
        point_masses.push(PointMass { at: 1.2, offset: V3::new(0.02, 0.2, -0.1), mass: 0.7, inertia });
        point_masses.push(PointMass { at: 0.5, offset: V3::new(0.0, -0.1, 0.1), mass: 0.3, inertia });
    }
    let body = BodySpec {
        name: "twisted".into(),
        start: V3::new(0.1, 0.0, -0.2),
        length: 1.2,
        frame: rotation_matrix(&V3::new(0.2, 0.1, -0.3)),
        section: sec,
        n_elements: 2,
        point_masses,
        twist: crate::Twist::none(),
    };
    let mut model = Model::new(&[body], &[], V3::new(0.3, -0.4, -9.8), Options::default()).unwrap();
    model.set_nodal_load(0, 4, NodalLoad { force: rng.v3(1.0), moment: rng.v3(1.0) }).unwrap();
    let mut q = model.reference_coordinates();
    // Rotations about a direction near z growing along the body past π; stored folded.
    let dir = V3::new(0.1, -0.05, 1.0).normalize();
    for (i, angle) in [(1usize, 2.2), (2, 2.9), (3, 3.5), (4, 4.1)] {
        let psi = crate::crv::rescale(&(dir * angle)).unwrap_or(dir * angle) + rng.v3(0.02);
        let k = 6 * (i - 1) + 3;
        q[k..k + 3].copy_from_slice(psi.as_slice());
    }
    let n = model.n_dof();
    let v: Vec<f64> = (0..n).map(|_| rng.next()).collect();
    let a: Vec<f64> = (0..n).map(|_| rng.next()).collect();
    check_iteration_matrix(&model, &q, &v, &a, "rescaled CRVs, iteration matrix");
    // Storing an end node on the other branch changes nothing but the parametrisation of its
    // own rows (the element maps it back onto its middle node's branch): unfold node 4 (stored
    // folded) and compare, rates transformed consistently.
    let mut r1 = vec![0.0; n];
    model.residual_inplace(0.0, &q, &v, &a, &mut r1);
    let k = 21;
    let psi4 = V3::new(q[k], q[k + 1], q[k + 2]);
    let m = crate::crv::BranchMap::new(&psi4, 1);
    let (mut q2, mut v2, mut a2) = (q.clone(), v.clone(), a.clone());
    q2[k..k + 3].copy_from_slice(m.apply().as_slice());
    let pd = V3::new(v[k], v[k + 1], v[k + 2]);
    let pdd = V3::new(a[k], a[k + 1], a[k + 2]);
    v2[k..k + 3].copy_from_slice((m.jac() * pd).as_slice());
    a2[k..k + 3].copy_from_slice((m.jac() * pdd + m.djac(&pd) * pd).as_slice());
    let mut r2 = vec![0.0; n];
    model.residual_inplace(0.0, &q2, &v2, &a2, &mut r2);
    // Rows of node 4's CRV transform with Jᵀ (virtual work); all other rows agree.
    let jt_r2 = m.jac().transpose() * V3::new(r2[k], r2[k + 1], r2[k + 2]);
    for i in 0..n {
        let (x, y) = if (k..k + 3).contains(&i) { (r1[i], jt_r2[i - k]) } else { (r1[i], r2[i]) };
        assert!((x - y).abs() < 1e-9 * (1.0 + x.abs()), "row {i}: {x} vs {y}");
    }
}

/// The one-pass residual and matrix equal the two separate evaluations, at ordinary states and at
/// large rotations (elements mapped across π take the separate residual path).
#[test]
fn fused_residual_and_matrix_equal_the_separate_calls() {
    for (seed, scale, springs, masses) in
        [(5, 1.0, false, false), (6, 15.0, false, false), (7, 1.0, true, true), (8, 15.0, true, true)]
    {
        let mut rng = Lcg(seed);
        let (model, q0, v, a, _) = random_model_full(&mut rng, 0.4, false, springs, masses);
        let n = model.n_dof();
        let dq: Vec<f64> = (0..n).map(|_| rng.next() * scale).collect();
        let mut q = q0.clone();
        model.retract_inplace(&q0, &dq, &mut q);
        let mapped = model
            .bodies
            .iter()
            .any(|b| (0..b.n_elements).any(|e| ElementState::gather(b, e, &q, None, None).is_mapped()));
        assert_eq!(mapped, scale > 1.0, "seed {seed}: the large-rotation state must map an element");
        let (c_m, c_c, c_k) = (1.0, 0.3, 0.02);
        let (mut r1, mut r2) = (vec![0.0; n], vec![0.0; n]);
        let (mut k1, mut k2) = (DenseMatrix::zeros(n, n), DenseMatrix::zeros(n, n));
        model.residual_inplace(0.0, &q, &v, &a, &mut r1);
        model.iteration_matrix_inplace(0.0, &q, &v, &a, c_m, c_c, c_k, &mut k1.view());
        model.residual_and_iteration_matrix_inplace(0.0, &q, &v, &a, &mut r2, c_m, c_c, c_k, &mut k2.view());
        let r_max = r1.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        for (x, y) in r1.iter().zip(&r2) {
            assert!((x - y).abs() <= 1e-14 * r_max, "seed {seed}: residual {x} vs {y}");
        }
        assert!(dense_rel_err(&k1, &k2) <= 1e-14, "seed {seed}: matrix differs");
        assert!(r_max > 0.0);
    }
}
