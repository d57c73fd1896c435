//! The one-surface linear UVLM is bit for bit the model before it took several surfaces: hashes
//! of every matrix and vector of `LinearUvlm` (influence, wake rows, force derivatives, the
//! reference state), of `evaluate` on a moved lattice with velocities, of the gust input, of the
//! wake nodes' derivatives and of the Laplace-domain transfer, on a flared wing with a hinge
//! column, flaps, an image plane and a loaded lattice, with and without the trailing-edge
//! segment's force and the wake closure; recorded on main before the change (commit e70b6a9).

use nalgebra::{Complex, DMatrix};
use uvlm::samples::FlaredWing;
use uvlm::*;

/// FNV-1a over the bit patterns.
fn hash(values: impl IntoIterator<Item = f64>, h: &mut u64) {
    for v in values {
        for b in v.to_bits().to_le_bytes() {
            *h ^= b as u64;
            *h = h.wrapping_mul(0x100000001b3);
        }
    }
}

fn hash_m(m: &DMatrix<f64>, h: &mut u64) {
    hash(m.iter().copied(), h);
}

fn hash_c(m: &DMatrix<Complex<f64>>, h: &mut u64) {
    hash(m.iter().flat_map(|z| [z.re, z.im]), h);
}

fn stations(wing: &FlaredWing, fold: f64) -> Vec<SpanStation> {
    let mut st = wing.stations(fold);
    for (j, s) in st.iter_mut().enumerate().take(5).skip(2) {
        s.flap = Some(StationFlap { chord_fraction: 0.3, deflection: (2.0 + j as f64).to_radians(), rate: 0.0 });
    }
    st
}

/// The linear model of the flared wing and everything it gives, hashed.
pub fn one_surface_linear(te_segment_force: bool, closure: bool) -> u64 {
    let wing = FlaredWing { aoa: 4f64.to_radians(), n_inner: 6, n_outer: 3, n_chordwise: 3, ..FlaredWing::default() };
    let lat = Lattice::from_stations(wing.spec(), &stations(&wing, 0.0)).unwrap();
    let mut p = UvlmParams::new(1.1, [0.0, -20.0, 0.5]);
    p.parallel = Parallel::Off;
    p.wake_core = CoreModel::Scully { fraction: 0.1 };
    p.te_segment_force = te_segment_force;
    p.images = vec![ImagePlane::through_origin([1.0, 0.0, 0.0])];
    let mut u = Uvlm::new(lat, p).unwrap();
    let lin = u.linearise(&LinearWake { row_lengths: vec![0.2, 0.25, 0.3, 0.5, 1.0], closure }).unwrap();
    let mut h = 0xcbf29ce484222325u64;
    hash(lin.gamma0().iter().copied(), &mut h);
    hash_m(&lin.aic, &mut h);
    hash(lin.row_delays.iter().copied(), &mut h);
    lin.row_normalwash.iter().for_each(|m| hash_m(m, &mut h));
    hash_m(&lin.force_gamma, &mut h);
    hash_m(&lin.force_gamma_dot, &mut h);
    lin.force_row.iter().for_each(|m| hash_m(m, &mut h));
    hash(lin.te_rings.iter().map(|&r| r as f64), &mut h);
    hash(lin.reference_residual.iter().copied(), &mut h);
    hash(lin.reference_forces.iter().copied(), &mut h);
    let mut moved = lin.lattice().clone();
    let vel = vec![StationVelocity { linear: [0.0, 0.1, 0.3].into(), angular: [0.05, 0.02, 0.0].into() }; 10];
    moved.update_stations(&stations(&wing, 0.02), Some(&vel)).unwrap();
    let (r, f) = lin.evaluate(&moved).unwrap();
    hash(r, &mut h);
    hash(f, &mut h);
    let g = lin.gust([0.1, 0.2, 1.0], [0.0, 1.0, 0.0]).unwrap();
    hash(g.normalwash.iter().copied(), &mut h);
    hash(g.collocation_delays.iter().copied(), &mut h);
    hash_m(&g.force, &mut h);
    hash(g.midpoint_delays.iter().copied(), &mut h);
    let wd = lin.wake_node_derivatives();
    wd.residual.iter().for_each(|m| hash_m(m, &mut h));
    wd.force.iter().for_each(|m| hash_m(m, &mut h));
    let s = Complex::new(0.3, 2.0);
    hash_c(&lin.normalwash_matrix(s), &mut h);
    hash_c(&lin.force_matrix(s), &mut h);
    h
}

/// The hashes of [`one_surface_linear`] for (te_segment_force, closure) = (false, false),
/// (true, false), (false, true), (true, true), on main before several surfaces (e70b6a9),
/// re-recorded when the load points took the regular terms on the filaments' axis extensions
/// (docs/uvlm.md §3), and again when the frozen wake's filaments took them too, with the AVX-512
/// kernels (other instruction sets round differently).
const MAIN_AVX512: [u64; 4] = [0xeb2dce4980b3aef1, 0xd0ed6fe9a98fe02a, 0x067712d2d35790a7, 0xca9b1fc45bb83bf6];

fn avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// The one-surface linear model is bit for bit main's (on an AVX-512 machine).
#[test]
fn one_surface_linear_is_bitwise_main() {
    let cases = [(false, false), (true, false), (false, true), (true, true)];
    for (c, (te, closure)) in cases.into_iter().enumerate() {
        let h = one_surface_linear(te, closure);
        println!("te_segment_force {te}, closure {closure}: {h:#018x}");
        if avx512() {
            assert_eq!(h, MAIN_AVX512[c], "te_segment_force {te}, closure {closure}: {h:#018x} differs from main");
        }
    }
}
