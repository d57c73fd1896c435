//! The output seam: a run hands every output step's geometry to its observer.

use harness::case::{CaseFile, Formulation};
use harness::run::{Observer, Snapshot};
use harness::scene::run_formulation_observed;

/// Keeps what a 3-D writer would need: time, node count, the last body's last node, and the
/// lattice's size and circulation.
#[derive(Default)]
struct Recorder {
    t: Vec<f64>,
    nodes: Vec<usize>,
    last_node: Vec<[f64; 3]>,
    frames_orthonormal: bool,
    rings: Vec<usize>,
    wake_rows: Vec<usize>,
}

impl Observer for Recorder {
    fn observe(&mut self, s: &Snapshot<'_>) -> Result<(), String> {
        assert_eq!(s.index, self.t.len());
        self.t.push(s.t);
        self.nodes.push(s.beams.iter().map(|b| b.positions.len()).sum());
        let last = s.beams.last().unwrap();
        self.last_node.push((*last.positions.last().unwrap()).into());
        self.frames_orthonormal = s
            .beams
            .iter()
            .flat_map(|b| &b.frames)
            .all(|r| (r.transpose() * r - nalgebra::Matrix3::identity()).amax() < 1e-6 && r.determinant() > 0.0);
        if let Some(uv) = s.aero {
            assert_eq!(uv.gamma().len(), uv.lattice().n_rings());
            self.rings.push(uv.lattice().n_rings());
            self.wake_rows.push(uv.wake().n_rows());
        }
        Ok(())
    }
}

fn case(name: &str, t_end: f64) -> harness::case::Case {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases");
    let overrides = [format!("t_end={t_end}").parse().unwrap()];
    CaseFile::read(&root.join(name)).unwrap().expand(&overrides).unwrap().remove(0).ancf
}

#[test]
fn every_output_step_reaches_the_observer_with_the_nodes_of_every_body() {
    let c = case("double_pendulum_c1_beta45.json", 0.05);
    for f in Formulation::ALL {
        let mut rec = Recorder::default();
        let out = run_formulation_observed(&c, f, &mut rec);
        assert!(out.error.is_none(), "{f}: {:?}", out.error);
        assert_eq!(rec.t.len(), out.rows.len(), "{f}");
        for (t, r) in rec.t.iter().zip(&out.rows) {
            assert_eq!(*t, r.t);
        }
        // ANCF: 5 two-node elements per body (6 nodes); GEBF: 5 three-node elements (11 nodes).
        let expected = match f {
            Formulation::Ancf => 2 * 6,
            Formulation::Gebf => 2 * 11,
        };
        assert!(rec.nodes.iter().all(|&n| n == expected), "{f}: {:?}", rec.nodes[0]);
        assert!(rec.frames_orthonormal, "{f}");
        // The free end of the last body is the tip the rows report.
        for (p, r) in rec.last_node.iter().zip(&out.rows) {
            let d = (0..3).map(|k| (p[k] - r.tip[k]).powi(2)).sum::<f64>().sqrt();
            assert!(d < 1e-12, "{f}: last node {p:?} vs tip {:?}", r.tip);
        }
    }
}

#[test]
fn an_aeroelastic_run_hands_over_its_lattice_and_growing_wake() {
    let c = case("wing_aoa5.json", 0.02);
    let mut rec = Recorder::default();
    let out = run_formulation_observed(&c, Formulation::Gebf, &mut rec);
    assert!(out.error.is_none(), "{:?}", out.error);
    assert_eq!(rec.rings.len(), out.rows.len());
    assert!(rec.rings.iter().all(|&n| n > 0 && n == rec.rings[0]));
    assert!(rec.wake_rows.windows(2).all(|w| w[1] >= w[0]), "{:?}", rec.wake_rows);
    assert!(rec.wake_rows.last().unwrap() > &0);
}
