//! The one-surface path is bit for bit the solver before several surfaces existed: hashes of
//! every circulation, nodal load, hinge moment and probe velocity of a run that touches every
//! option (flap, hinge column, image plane, free wake with a core, disturbance, trailing-edge
//! segment force, frozen far wake with sub-iterations, steady solve, finite steady wake,
//! prefilled wake), recorded on main before the change (commit ac75eb7) and re-recorded when the
//! load points' induction took the regular form on the filaments' axis extensions
//! (`axis_extension.rs`, docs/uvlm.md §3).

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

fn record(u: &Uvlm, h: &mut u64) {
    hash(u.gamma().iter().copied(), h);
    hash(u.gamma_dot().iter().copied(), h);
    hash(u.loads().nodal.iter().flatten().copied(), h);
    hash(u.loads().strip.iter().flatten().copied(), h);
    hash(u.loads().total_force(), h);
    hash(u.velocity_at([3.0, -2.0, 0.4]), h);
    hash([u.hinge_moment(2..=5).unwrap()], h);
}

/// The run: returns the hash over all steps.
pub fn one_surface_run(build: impl Fn(Lattice, UvlmParams) -> Uvlm, free: bool, frozen: bool) -> u64 {
    let wing = FlaredWing { aoa: 4f64.to_radians(), n_inner: 12, n_outer: 4, ..FlaredWing::default() };
    let stations = |k: usize| {
        let mut st = wing.stations(0.03 * k as f64);
        for (j, s) in st.iter_mut().enumerate().take(6).skip(2) {
            s.flap = Some(StationFlap { chord_fraction: 0.25, deflection: (2.0 + j as f64).to_radians(), rate: 0.1 });
        }
        st
    };
    let lat = Lattice::from_stations(wing.spec(), &stations(0)).unwrap();
    let mut p = UvlmParams::new(1.1, [0.0, -20.0, 0.5]);
    p.parallel = Parallel::Off;
    p.n_wake_rows = 7;
    p.wake_convection = if free { WakeConvection::Free } else { WakeConvection::Prescribed };
    p.wake_core = CoreModel::Scully { fraction: 0.1 };
    p.te_segment_force = true;
    p.wake_closure = true;
    p.wake_reuse = if frozen { WakeReuse::Frozen } else { WakeReuse::Recompute };
    p.images = vec![ImagePlane::through_origin([1.0, 0.0, 0.0])];
    let mut u = build(lat, p);
    u.set_disturbance(Some(Box::new(|x: [f64; 3], t: f64| [0.0, 0.1 * x[0], (x[1] + 20.0 * t).sin()])));
    let mut h = 0xcbf29ce484222325u64;
    u.solve_steady().unwrap();
    record(&u, &mut h);
    u.set_steady_wake(SteadyWake::Finite { length: 5.0 }).unwrap();
    u.solve_steady().unwrap();
    record(&u, &mut h);
    u.prefill_wake(0.02).unwrap();
    let vel = vec![StationVelocity { linear: [0.0, 0.0, 0.3].into(), angular: [0.05, 0.0, 0.0].into() }; 17];
    for k in 1..=10 {
        u.advance_wake(0.02).unwrap();
        u.update_stations(&stations(k + 1), Some(&vel)).unwrap();
        u.solve_step().unwrap();
        u.update_stations(&stations(k), Some(&vel)).unwrap();
        u.solve_step().unwrap();
        u.commit_step().unwrap();
        record(&u, &mut h);
    }
    h
}

/// The hashes of [`one_surface_run`] (re-recorded with the load points' regular kernel, and again
/// when the march's wake filaments took it at the load points), with the
/// AVX-512 kernels (the dispatch of `biot_savart.rs`; other instruction sets round differently).
const MAIN_AVX512: [u64; 4] = [0x0e566fbb8bdc9289, 0x55e113d74778c53e, 0x5c478372197e3fea, 0xa563e898f0a79a32];

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

/// `Uvlm::new` and a one-surface `Uvlm::with_surfaces` are bit for bit main's solver (on an
/// AVX-512 machine; elsewhere they are bit for bit each other).
#[test]
fn one_surface_is_bitwise_main() {
    let cases = [(false, false), (true, false), (false, true), (true, true)];
    for (c, (free, frozen)) in cases.into_iter().enumerate() {
        let h_new = one_surface_run(|l, p| Uvlm::new(l, p).unwrap(), free, frozen);
        let h_with = one_surface_run(|l, p| Uvlm::with_surfaces(vec![l], p).unwrap(), free, frozen);
        assert_eq!(h_new, h_with, "free {free}, frozen {frozen}: new vs with_surfaces");
        if avx512() {
            assert_eq!(h_new, MAIN_AVX512[c], "free {free}, frozen {frozen}: {h_new:#018x} differs from main");
        }
    }
}
