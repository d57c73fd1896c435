//! The flared-hinge wing of docs/cases.md §2 (Table 3–4) under gravity alone: clamped inner body
//! (12 m, 12 elements) and outer body (4 m, 4 elements) on a 10° flared hinge; prints the
//! wingtip height and fold angle. A structural smoke test of the aeroelastic case.
use ancf::{BodySpec, JointSpec, Model, Options, Section};
use genalpha::IntegratorParams;
use nalgebra::{Matrix3, Vector3};

fn main() {
    let section = Section {
        mass: 0.75,
        rho_ixx: 0.1,
        rho_iyy: 0.01,
        rho_izz: 0.09,
        ea: 1e7,
        ga_y: 5e6,
        ga_z: 5e6,
        gj: 1e4,
        ei_yy: 2e4,
        ei_zz: 5e6,
        cg_offset: [0.0; 2],
    };
    let body = |name: &str, x0: f64, length: f64, n_elements: usize| BodySpec {
        name: name.into(),
        start: Vector3::new(x0, 0.0, 0.0),
        length,
        frame: Matrix3::identity(),
        section,
        n_elements,
        point_masses: Vec::new(),
        twist: ancf::Twist::none(),
    };
    let bodies = [body("inner", 0.0, 12.0, 12), body("outer", 12.0, 4.0, 4)];
    let joints =
        [JointSpec::Clamp { body: 0 }, JointSpec::FlaredHinge { parent: 0, child: 1, beta: 10f64.to_radians() }];
    let mut model = Model::new(&bodies, &joints, Vector3::new(0.0, 0.0, -9.8), Options::default()).expect("valid");
    let mut params = IntegratorParams::new(0.8, 0.01);
    params.newton.estimate_convergence = std::env::var("NOEST").is_err();
    params.newton.reuse_factorization = std::env::var("FULL").is_err();
    let mut ga = model.integrator(params).expect("valid");
    let mut s = model.initial_state();
    ga.initialize(&model, &mut s).expect("consistent");
    for k in 1..=500 {
        if let Err(e) = ga.step(&mut model, &mut s) {
            println!("{e}");
            break;
        }
        if k % 50 == 0 {
            let tip = model.tip_position(&s.q);
            let fold = model.fold_angle(&s.q, 1).expect("flared hinge").to_degrees();
            let e = model.energies(&s.q, &s.v);
            println!(
                "t {:5.2} tip z {:8.4} fold {:8.3} deg  E {:.4e}  residual {:.1e}",
                s.t,
                tip.z,
                fold,
                e.total(),
                model.constraint_residual(&s.q)
            );
        }
    }
    println!("{:?}", ga.stats());
}
