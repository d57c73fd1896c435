//! The gust input of the linear UVLM (`LinearUvlm::gust`) at s = 0 against the steady solver in
//! a uniform upwash: the frozen wake's rows along the free stream closed by legs are the steady
//! solver's semi-infinite legs, and the loads are bilinear in the circulations and the external
//! velocity, so a central difference of the steady solver in the upwash is the linear model's
//! response exactly (to round-off and the difference of the two wakes' cores).

use nalgebra::{Complex, DVector};
use uvlm::samples::{SpanSpacing, rectangular_wing};
use uvlm::*;

type C = Complex<f64>;

#[test]
fn gust_input_at_rest_is_the_steady_upwash_response() {
    let stations = rectangular_wing(0.0, 4.0, 1.0, 8, SpanSpacing::HalfCosine);
    let lat = Lattice::from_stations(LatticeSpec::new(4), &stations).unwrap();
    // Pitched flow: a non-zero steady circulation, so that the gust's Joukowski term matters.
    let v = [10.0 * 0.1f64.cos(), 0.0, 10.0 * 0.1f64.sin()];
    let mut p = UvlmParams::new(1.2, v);
    p.images = vec![ImagePlane::through_origin([0.0, 1.0, 0.0])];
    let mut uv = Uvlm::new(lat.clone(), p.clone()).unwrap();
    let lin = uv.linearise(&LinearWake::uniform(30, 0.1, true)).unwrap();
    let d = [0.0, 0.0, 1.0];
    let g = lin.gust(d, [-1.0, 0.0, 0.0]).unwrap();
    let s = C::new(0.0, 0.0);
    let n = lin.normalwash_matrix(s);
    let r = DVector::from_vec(g.normalwash_at(s));
    let dgamma = -n.lu().solve(&r).unwrap();
    let f_lin: DVector<C> = lin.force_matrix(s) * &dgamma + DVector::from_vec(g.force_at(s));
    // The steady solver in a uniform upwash ±w.
    let w = 1e-3;
    let mut forces = Vec::new();
    for sgn in [1.0, -1.0] {
        let mut u = Uvlm::new(lat.clone(), p.clone()).unwrap();
        u.set_disturbance(Some(Box::new(Uniform([0.0, 0.0, sgn * w]))));
        let l = u.solve_steady().unwrap();
        forces.push(DVector::from_iterator(3 * l.nodal.len(), l.nodal.iter().flatten().copied()));
    }
    let f_nl = (&forces[0] - &forces[1]) / (2.0 * w);
    let f_re = f_lin.map(|x| x.re);
    let total = |f: &DVector<f64>| [0, 1, 2].map(|c| (0..f.len() / 3).map(|k| f[3 * k + c]).sum::<f64>());
    let (tl, tn) = (total(&f_re), total(&f_nl));
    let err = (&f_re - &f_nl).amax() / f_nl.amax();
    println!(
        "total force per unit upwash: linear {tl:?}, steady {tn:?}; largest nodal difference {err:.2e} of the largest"
    );
    assert!(f_lin.iter().all(|x| x.im == 0.0));
    assert!(err < 1e-6, "{err}");
}
