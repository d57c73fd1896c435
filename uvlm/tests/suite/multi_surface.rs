//! Several lifting surfaces in one influence system (docs/uvlm.md §16): a full-span wing as two
//! half-wings meeting at the root equals one surface across the plane of symmetry and the mirror
//! image; a tail in the wing's downwash; the per-surface API and its errors.

use approx::assert_relative_eq;
use uvlm::samples::{SpanSpacing, elliptic_half_wing, rectangular_wing};
use uvlm::*;

/// Largest |a − b| over the largest |a|.
#[track_caller]
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

/// Component `q` of every strip force.
fn strips(loads: &Loads, q: usize) -> Vec<f64> {
    loads.strip.iter().map(|f| f[q]).collect()
}

/// The three meshes of one AR-8 rectangular wing (chord 1, 2·n_half strips clustered at the
/// tips and the root, `nc` chordwise): (a) one surface from −b/2 to b/2, (b) two half-wings
/// meeting at the root (the root station is the same station), (c) the right half with a
/// symmetry plane.
struct ThreeWings {
    a: Uvlm,
    b: Uvlm,
    c: Uvlm,
    full: Vec<SpanStation>,
    n_half: usize,
}

fn three_wings(params: &UvlmParams, n_half: usize, nc: usize) -> ThreeWings {
    let half_st = rectangular_wing(0.0, 4.0, 1.0, n_half, SpanSpacing::Cosine);
    // The left half mirrors the right one station for station (so that the root strips match).
    let mut full: Vec<SpanStation> = half_st[1..]
        .iter()
        .rev()
        .map(|s| SpanStation { origin: [s.origin.x, -s.origin.y, s.origin.z].into(), ..*s })
        .collect();
    full.extend_from_slice(&half_st);
    let spec = LatticeSpec::new(nc);
    let lat = |st: &[SpanStation]| Lattice::from_stations(spec, st).unwrap();
    let a = Uvlm::new(lat(&full), params.clone()).unwrap();
    let b = Uvlm::with_surfaces(vec![lat(&full[..=n_half]), lat(&full[n_half..])], params.clone()).unwrap();
    let mut pc = params.clone();
    pc.images.push(ImagePlane::through_origin([0.0, 1.0, 0.0]));
    let c = Uvlm::new(lat(&full[n_half..]), pc).unwrap();
    ThreeWings { a, b, c, full, n_half }
}

impl ThreeWings {
    /// (a) against (b) and (c): circulations, total lift and drag, and the spanwise lift and
    /// drag distribution (strip forces along z and x), to `tol` of the largest.
    fn compare(&self, tol: f64, what: &str) {
        let (n, nh) = (2 * self.n_half, self.n_half);
        let nc = self.a.lattice().n_chordwise();
        // (b)'s global numbering is left then right; (a)'s is row by row over the whole span.
        let mut gb = Vec::new();
        let mut gc = Vec::new();
        let (left, right) = (self.b.surface(0).unwrap().rings(), self.b.surface(1).unwrap().rings());
        for i in 0..nc {
            for j in 0..n {
                gb.push(if j < nh {
                    self.b.gamma()[left.start + i * nh + j]
                } else {
                    self.b.gamma()[right.start + i * nh + j - nh]
                });
                gc.push(self.c.gamma()[i * nh + if j < nh { nh - 1 - j } else { j - nh }]);
            }
        }
        let ga = self.a.gamma();
        assert!(rel_diff(ga, &gb) <= tol, "{what}: Γ (a) vs (b) {:.2e}", rel_diff(ga, &gb));
        assert!(rel_diff(ga, &gc) <= tol, "{what}: Γ (a) vs (c) {:.2e}", rel_diff(ga, &gc));
        let (fa, fb, fc) = (self.a.loads().total_force(), self.b.loads().total_force(), self.c.loads().total_force());
        for q in [0, 2] {
            assert_relative_eq!(fa[q], fb[q], max_relative = tol);
            assert_relative_eq!(fa[q], 2.0 * fc[q], max_relative = tol);
        }
        for q in [0, 2] {
            let sa = strips(self.a.loads(), q);
            // (b)'s concatenated strips are (a)'s; (c)'s mirrored.
            let sb = strips(self.b.loads(), q);
            let sc: Vec<f64> =
                (0..n).map(|j| self.c.loads().strip[if j < nh { nh - 1 - j } else { j - nh }][q]).collect();
            let (db, dc) = (rel_diff(&sa, &sb), rel_diff(&sa, &sc));
            println!("{what}: strip forces [{q}] (a)-(b) {db:.1e}, (a)-(c) {dc:.1e}");
            assert!(db <= tol && dc <= tol, "{what}: strips[{q}] (a) vs (b) {db:.2e}, (a) vs (c) {dc:.2e}");
        }
        // The right half-wing of (b) is (c) in every component, side force included: each
        // carries its root chordwise vortex (±Γ_root) alone, which (a) nets out (docs/uvlm.md §16).
        let (sr, sc) = (&self.b.surface(1).unwrap().loads().strip, &self.c.loads().strip);
        let flat = |s: &[[f64; 3]]| s.iter().flatten().copied().collect::<Vec<f64>>();
        assert!(
            rel_diff(&flat(sc), &flat(sr)) <= tol,
            "{what}: right half (b) vs (c) {:.2e}",
            rel_diff(&flat(sc), &flat(sr))
        );
        println!("{what}: Γ (a)-(b) {:.1e}, (a)-(c) {:.1e}", rel_diff(ga, &gb), rel_diff(ga, &gc));
    }
}

/// Two half-wings meeting at the root = one surface across the plane of symmetry = the mirror
/// image, to 1e-10 of the largest value: steady (semi-infinite legs), then impulsive unsteady
/// steps with a plunge velocity, prescribed and free wake.
///
/// Why (b) = (a): at the root the two half-wings' chordwise bound edges (and trailing legs, and
/// wake legs) coincide node for node and carry Γ_left and −Γ_right; by linearity two coincident
/// filaments induce what one of strength Γ_left − Γ_right induces, everywhere off the filament,
/// and the midpoints on it are inside both filaments' cut-off. Only the order of the sums
/// changes, so the results agree to round-off.
#[test]
fn two_half_wings_equal_one_surface_and_the_mirror_image() {
    let alpha = 5f64.to_radians();
    for convection in [WakeConvection::Prescribed, WakeConvection::Free] {
        let mut p = UvlmParams::new(1.2, [10.0 * alpha.cos(), 0.0, 10.0 * alpha.sin()]);
        p.n_wake_rows = 6;
        p.wake_convection = convection;
        p.wake_core = CoreModel::Scully { fraction: 0.1 };
        let mut w = three_wings(&p, 8, 4);
        w.a.solve_steady().unwrap();
        w.b.solve_steady().unwrap();
        w.c.solve_steady().unwrap();
        w.compare(1e-10, "steady");
        let nh = w.n_half;
        let plunge = |n: usize| vec![StationVelocity { linear: [0.0, 0.0, -0.5].into(), ..Default::default() }; n];
        let full = w.full.clone();
        for k in 0..6 {
            w.a.update_stations(&full, Some(&plunge(full.len()))).unwrap();
            w.b.update_stations_of(0, &full[..=nh], Some(&plunge(nh + 1))).unwrap();
            w.b.update_stations_of(1, &full[nh..], Some(&plunge(nh + 1))).unwrap();
            w.c.update_stations(&full[nh..], Some(&plunge(nh + 1))).unwrap();
            for u in [&mut w.a, &mut w.b, &mut w.c] {
                u.step(0.05).unwrap();
            }
            w.compare(1e-10, &format!("{convection:?} step {k}"));
        }
    }
}
