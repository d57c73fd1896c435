use ancf::statics::StaticsParams;
use ancf::{Curvature, JointSpec, Model, Options, PointLoad, samples};
use nalgebra::Vector3;

#[test]
fn explore_flared_static() {
    let sec = samples::pendulum_section(1.0);
    for kappa in [0.0, 100.0, 1000.0] {
        for pf in [1.0, 10.0] {
            for n in [2, 5, 10, 20, 40] {
                let (mut b, mut j, _) = samples::double_pendulum(1.0, 45.0, n);
                j[0] = JointSpec::Clamp { body: 0 };
                b[0].section = sec;
                let opts = Options { curvature: Curvature::Hybrid, penalty_factor: pf, shear_gradient_factor: kappa, ..Default::default() };
                let mut m = Model::new(&b, &j, Vector3::zeros(), opts).unwrap();
                let f = 1e-3;
                m.set_point_loads(&[PointLoad::force(1, 0.5, Vector3::new(0.0, f, 0.0))]).unwrap();
                let sol = m.solve_statics(StaticsParams { n_load_steps: 1, ..Default::default() }).unwrap();
                let tip = m.tip_position(&sol.q);
                let (l1, l2, ei, ga): (f64, f64, f64, f64) = (0.5, 0.5, sec.ei_zz, sec.ga_y);
                let mm = 0.5 * f;
                let exact = f * l2.powi(3) / (3.0 * ei)
                    + f * l1.powi(3) / (3.0 * ei)
                    + mm * l1 * l1 / (2.0 * ei)
                    + 0.5 * (f * l1 * l1 / (2.0 * ei) + mm * l1 / ei)
                    + f * (l1 + l2) / ga;
                println!("kappa {kappa} pf {pf} n={n}: rel err {:.3e}", tip.y / exact - 1.0);
            }
        }
    }
}
