//! The ParaView files of the paper's wing read back by VTK's own XML reader
//! (`vtkXMLPolyDataReader`, Python `vtk` from the test's virtual environment): numbers of points,
//! cells and time steps of every family, and the data arrays ParaView colours by.

use std::process::Command;

use super::external::{root, temp_dir, venv_python};

/// Reads every `.pvd` under argv[1] and each file it lists with vtkXMLPolyDataReader; prints
/// one line per family: `<formulation> <family> <steps> <points,lines,polys of the first step>
/// <of the last step> <point arrays>|<cell arrays>` of the last step.
const READER: &str = r#"
import sys, os, xml.etree.ElementTree as ET
import vtk
root = sys.argv[1]
for f in sorted(os.listdir(root)):
    d = os.path.join(root, f)
    for pvd in sorted(x for x in os.listdir(d) if x.endswith(".pvd")):
        sets = ET.parse(os.path.join(d, pvd)).getroot().find("Collection").findall("DataSet")
        times = [float(s.get("timestep")) for s in sets]
        assert all(b > a for a, b in zip(times, times[1:])), pvd
        counts = []
        for s in sets:
            r = vtk.vtkXMLPolyDataReader()
            r.SetFileName(os.path.join(d, s.get("file")))
            r.Update()
            assert r.GetErrorCode() == 0, s.get("file")
            o = r.GetOutput()
            counts.append((o.GetNumberOfPoints(), o.GetNumberOfLines(), o.GetNumberOfPolys()))
        pd, cd = o.GetPointData(), o.GetCellData()
        pa = ",".join(pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays()))
        ca = ",".join(cd.GetArrayName(i) for i in range(cd.GetNumberOfArrays()))
        first, last = counts[0], counts[-1]
        print(f, pvd[:-4], len(sets), "%d,%d,%d" % first, "%d,%d,%d" % last, pa + "|" + ca, "%.6g" % times[-1])
"#;

#[test]
fn vtk_files_of_the_papers_wing_parse_with_vtks_reader() {
    let Some(py) = venv_python("vtk_files_of_the_papers_wing_parse_with_vtks_reader") else { return };
    let out = temp_dir("vtk-parse");
    // The paper's wing for its first second: 101 output rows (output_dt 0.01 s), so the default
    // stride max(1, 101 / 100) = 1 writes all of them.
    let o = Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(["run", "cases/wing_aoa5.json", "--set", "t_end=1", "--vtk", "--out"])
        .arg(&out)
        .current_dir(root())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The run's folder is named after its variant (`--set`): the one folder of the case.
    let dir = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("wing_aoa5")) && p.join("vtk").is_dir())
        .expect("the run wrote its vtk folder");
    let r = Command::new(&py).args(["-c", READER]).arg(dir.join("vtk")).output().unwrap();
    let text = String::from_utf8_lossy(&r.stdout).to_string();
    assert!(r.status.success(), "{}\n{}", text, String::from_utf8_lossy(&r.stderr));
    eprintln!("{text}");
    // Per formulation and family: steps, counts (points, lines, polys) of the first and the last
    // step, arrays of the last. The beams: ANCF 12 + 4 elements (13 + 5 nodes), GEBF 6 + 2
    // three-node elements (13 + 5 nodes): 18 points, one polyline per body. The ribbon: two
    // points per node, one quad per node interval (12 + 4). The lattice: 4 × 32 panels on
    // 5 × 33 ring nodes. The wake: empty at t = 0, 40 rows × 32 (its truncation) after 100 steps,
    // on 41 × 33 nodes.
    let beams = "e1,e2,e3,s,body|";
    for f in ["ancf", "gebf"] {
        let expect = [
            format!("{f} beams 101 18,2,0 18,2,0 {beams} 1"),
            format!("{f} lattice 101 165,0,128 165,0,128 |gamma,delta_p 1"),
            format!("{f} ribbon 101 36,0,16 36,0,16 s,body| 1"),
            format!("{f} wake 101 33,0,0 1353,0,1280 |gamma 1"),
        ];
        for e in expect {
            assert!(text.lines().any(|l| l.trim() == e), "expected `{e}` in\n{text}");
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}
