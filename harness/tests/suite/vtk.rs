//! `harness run --vtk`: ParaView files of the beams, the lattice and the wake, with `.pvd` time
//! series, checked against the run's CSV.

use crate::common::root;
use std::path::Path;
use std::process::Command;

fn run(case: &str, t_end: &str, out: &Path, extra: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(["run", case, "--set", &format!("t_end={t_end}"), "--vtk", "--out"])
        .arg(out)
        .args(extra)
        .current_dir(root())
        .output()
        .expect("binary runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The integer value of attribute `name` (first occurrence).
fn attr(xml: &str, name: &str) -> usize {
    let key = format!("{name}=\"");
    let i = xml.find(&key).unwrap_or_else(|| panic!("no {name}")) + key.len();
    xml[i..].split('"').next().unwrap().parse().unwrap()
}

/// The numbers of the data array whose opening tag contains `tag`.
fn array(xml: &str, tag: &str) -> Vec<f64> {
    let mut open = xml.find(tag).unwrap_or_else(|| panic!("no {tag}"));
    if !tag.contains('=') {
        // An element holding the array (`<Points>`): skip to the array's tag.
        open += xml[open..].find("<DataArray").unwrap();
    }
    let start = open + xml[open..].find('>').unwrap() + 1;
    let end = start + xml[start..].find("</DataArray>").unwrap();
    xml[start..end].split_whitespace().map(|v| v.parse().unwrap()).collect()
}

/// The `.pvd` entries: (time, file).
fn collection(pvd: &str) -> Vec<(f64, String)> {
    pvd.lines()
        .filter(|l| l.starts_with("<DataSet"))
        .map(|l| {
            let field = |k: &str| {
                let key = format!("{k}=\"");
                let i = l.find(&key).unwrap() + key.len();
                l[i..].split('"').next().unwrap().to_string()
            };
            (field("timestep").parse().unwrap(), field("file"))
        })
        .collect()
}

/// Check one family's collection: every listed file exists, times increase; returns the entries.
fn check_family(dir: &Path, family: &str) -> Vec<(f64, String)> {
    let steps = collection(&read(&dir.join(format!("{family}.pvd"))));
    assert!(!steps.is_empty(), "{family}: empty collection");
    assert!(steps.windows(2).all(|w| w[1].0 > w[0].0), "{family}: times not increasing");
    let files = std::fs::read_dir(dir)
        .unwrap()
        .filter(|e| {
            let n = e.as_ref().unwrap().file_name().to_string_lossy().to_string();
            n.starts_with(&format!("{family}_")) && n.ends_with(".vtp")
        })
        .count();
    assert_eq!(files, steps.len(), "{family}: files written vs listed");
    for (_, f) in &steps {
        assert!(dir.join(f).exists(), "{f}");
    }
    steps
}

/// The CSV's tip at time `t`.
fn csv_tip(csv: &str, t: f64) -> [f64; 3] {
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let (ct, cx, cy, cz) = (col("t"), col("tip_x"), col("tip_y"), col("tip_z"));
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap_or(f64::NAN)).collect();
        if (v[ct] - t).abs() < 1e-9 {
            return [v[cx], v[cy], v[cz]];
        }
    }
    panic!("no CSV row at t = {t}");
}

#[test]
fn vtk_pendulum_beams_match_the_csv_tip() {
    let out = std::env::temp_dir().join(format!("harness-vtk-pendulum-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    run("cases/double_pendulum_c1_beta45.json", "0.02", &out, &["--vtk-stride", "3"]);
    // `--set` runs write to a folder named after the overrides.
    let case = out.join("double_pendulum_c1_beta45__set_t_end=0.02");
    for (f, nodes) in [("ancf", 2 * 6), ("gebf", 2 * 11)] {
        let dir = case.join("vtk").join(f);
        let steps = check_family(&dir, "beams");
        assert!(!dir.join("lattice.pvd").exists() && !dir.join("wake.pvd").exists(), "{f}");
        // 11 output rows (t = 0 .. 0.02, dt 2 ms), every 3rd: rows 0, 3, 6, 9.
        assert_eq!(steps.len(), 4, "{f}");
        let csv = read(&case.join(format!("{f}.csv")));
        for (t, file) in &steps {
            let x = read(&dir.join(file));
            assert_eq!(attr(&x, "NumberOfPoints"), nodes, "{f} {file}");
            assert_eq!(attr(&x, "NumberOfLines"), 2, "{f} {file}");
            for a in ["e1", "e2", "e3"] {
                assert_eq!(array(&x, &format!("Name=\"{a}\"")).len(), 3 * nodes, "{f} {file} {a}");
            }
            assert_eq!(array(&x, "Name=\"s\"").len(), nodes);
            let p = array(&x, "<Points>");
            assert_eq!(p.len(), 3 * nodes);
            let tip = csv_tip(&csv, *t);
            for k in 0..3 {
                assert!(
                    (p[3 * nodes - 3 + k] - tip[k]).abs() < 1e-9,
                    "{f} t = {t}: {:?} vs {tip:?}",
                    &p[3 * nodes - 3..]
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn vtk_wing_writes_lattice_and_wake() {
    let out = std::env::temp_dir().join(format!("harness-vtk-wing-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    run("cases/wing_aoa5.json", "0.03", &out, &["--formulation", "gebf"]);
    let dir = out.join("wing_aoa5__only-gebf__set_t_end=0.03").join("vtk").join("gebf");
    let beams = check_family(&dir, "beams");
    let lattice = check_family(&dir, "lattice");
    let wake = check_family(&dir, "wake");
    let ribbon = check_family(&dir, "ribbon");
    assert_eq!(ribbon.len(), beams.len());
    // The chord ribbon: two points per beam node, `chord` apart (1 m), one quad per node interval.
    for (_, file) in &ribbon {
        let x = read(&dir.join(file));
        let p = array(&x, "<Points>");
        let n = attr(&x, "NumberOfPoints");
        assert_eq!(n, 2 * 18);
        assert_eq!(attr(&x, "NumberOfPolys"), 16);
        for k in 0..n / 2 {
            let d: f64 = (0..3).map(|i| (p[6 * k + i] - p[6 * k + 3 + i]).powi(2)).sum::<f64>().sqrt();
            assert!((d - 1.0).abs() < 1e-12, "chord {d}");
        }
    }
    // The default stride: max(1, 4 output rows / 100) = 1, every row.
    assert_eq!(beams.len(), 4);
    assert_eq!(beams.len(), lattice.len());
    assert_eq!(beams.len(), wake.len());
    let mut polys = Vec::new();
    for (_, file) in &lattice {
        let x = read(&dir.join(file));
        let n_polys = attr(&x, "NumberOfPolys");
        assert!(n_polys > 0);
        assert_eq!(array(&x, "Name=\"gamma\"").len(), n_polys);
        let dp = array(&x, "Name=\"delta_p\"");
        assert_eq!(dp.len(), n_polys);
        assert!(dp.iter().all(|v| v.is_finite()));
        assert_eq!(array(&x, "<Points>").len(), 3 * attr(&x, "NumberOfPoints"));
        assert_eq!(array(&x, "Name=\"connectivity\"").len(), 4 * n_polys);
    }
    for (_, file) in &wake {
        let x = read(&dir.join(file));
        let n_polys = attr(&x, "NumberOfPolys");
        assert_eq!(array(&x, "Name=\"gamma\"").len(), n_polys);
        assert_eq!(array(&x, "Name=\"connectivity\"").len(), 4 * n_polys);
        polys.push(n_polys);
    }
    // The wake grows.
    assert!(polys.windows(2).all(|w| w[1] >= w[0]) && polys.last() > polys.first(), "{polys:?}");
    let _ = std::fs::remove_dir_all(&out);
}
