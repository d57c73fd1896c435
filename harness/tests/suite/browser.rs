//! The report in a real browser: headless Chromium opens `index.html` of a generated report (the
//! paper's wing and the c = 1, β = 45° pendulum, 0.5 s each) from `file://`, with no network.
//! Checks: every linked file exists; the page runs with no console error and no error caught by
//! its own handler; every 3-D view draws (the page counts the inked pixels of each canvas); and a
//! screenshot shows the drawing (pixels in the formulations' colours that a screenshot of the
//! same page without its script does not have).

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use super::external::{chromium, copy_tree, root, temp_dir, venv_python};

const TEST: &str = "report_loads_and_draws_in_headless_chromium";

/// How long one Chromium run may take before it counts as hung. A run takes 1–3 s here; a
/// headless Chromium now and then stalls with no CPU use and never exits.
const CHROME_DEADLINE: Duration = Duration::from_secs(90);
/// Runs after a hang before the test gives up.
const CHROME_TRIES: usize = 3;

/// Run Chromium headless on `url` with `extra` flags and a fresh profile under `dir`. A run that
/// passes [`CHROME_DEADLINE`] is killed with its whole process group and started again, up to
/// [`CHROME_TRIES`] times; a hang on every try fails the test, naming the url.
fn chrome(exe: &Path, dir: &Path, url: &str, extra: &[&str]) -> Output {
    for attempt in 0..CHROME_TRIES {
        let run = dir.join(format!("chrome-{attempt}"));
        let _ = std::fs::remove_dir_all(&run);
        std::fs::create_dir_all(&run).unwrap();
        // Files, not pipes: a killed browser's children cannot keep a reader waiting.
        let (out_path, err_path) = (run.join("stdout"), run.join("stderr"));
        let mut child = Command::new(exe)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--enable-logging=stderr",
                "--v=0",
                "--virtual-time-budget=8000",
            ])
            .arg(format!("--user-data-dir={}", run.join("profile").display()))
            .args(extra)
            .arg(url)
            .stdin(Stdio::null())
            .stdout(std::fs::File::create(&out_path).unwrap())
            .stderr(std::fs::File::create(&err_path).unwrap())
            .process_group(0)
            .spawn()
            .expect("chromium starts");
        let start = Instant::now();
        let status = loop {
            if let Some(status) = child.try_wait().unwrap() {
                break Some(status);
            }
            if start.elapsed() > CHROME_DEADLINE {
                break None;
            }
            std::thread::sleep(Duration::from_millis(100));
        };
        match status {
            Some(status) => {
                return Output {
                    status,
                    stdout: std::fs::read(&out_path).unwrap(),
                    stderr: std::fs::read(&err_path).unwrap(),
                };
            }
            None => {
                // The group holds the browser and every renderer and helper it started.
                let _ = Command::new("kill").args(["-KILL", &format!("-{}", child.id())]).status();
                let _ = child.wait();
                eprintln!("chromium hung for {CHROME_DEADLINE:?} on {url} (try {}); killed", attempt + 1);
            }
        }
    }
    panic!("chromium hung on all {CHROME_TRIES} tries on {url}");
}

/// Every relative `href="…"` and `src="…"` of `html`.
fn links(html: &str) -> Vec<String> {
    let mut v = Vec::new();
    for key in ["href=\"", "src=\""] {
        let mut rest = html;
        while let Some(i) = rest.find(key) {
            rest = &rest[i + key.len()..];
            let end = rest.find('"').unwrap_or(rest.len());
            let l = &rest[..end];
            if !(l.starts_with('#') || l.contains("://") || l.starts_with("data:")) {
                v.push(l.to_string());
            }
        }
    }
    v
}

/// Compares two screenshots with VTK's PNG reader: prints the number of pixels that differ and,
/// among them, the pixels in the formulations' colours (ANCF blue, GEBF orange, ±40 per channel).
const COMPARE: &str = r#"
import sys, vtk
from vtk.util.numpy_support import vtk_to_numpy
def load(p):
    r = vtk.vtkPNGReader(); r.SetFileName(p); r.Update()
    o = r.GetOutput(); w, h, _ = o.GetDimensions()
    a = vtk_to_numpy(o.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3].astype(int)
    return a
on, off = load(sys.argv[1]), load(sys.argv[2])
diff = (abs(on - off).sum(axis=2) > 30)
def near(c):
    return (abs(on - c) <= 40).all(axis=2)
col = near((0, 114, 178)) | near((213, 94, 0))
print(int(diff.sum()), int((diff & col).sum()), on.shape[1], on.shape[0])
"#;

#[test]
fn report_loads_and_draws_in_headless_chromium() {
    let Some(exe) = chromium(TEST) else { return };
    let Some(py) = venv_python(TEST) else { return };
    let dir = temp_dir("browser");
    // A report of two cases: their files, the references they read.
    let cases = dir.join("cases");
    copy_tree(&root().join("cases/reference"), &cases.join("reference"));
    for c in ["wing_aoa5.json", "double_pendulum_c1_beta45.json"] {
        std::fs::copy(root().join("cases").join(c), cases.join(c)).unwrap();
    }
    let out = dir.join("reports");
    let o = Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(["all", "--quick", "--set", "t_end=0.5", "--cases"])
        .arg(&cases)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    // The gate windows reach past 0.5 s, so the gate fails (exit 1); the report is written.
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", String::from_utf8_lossy(&o.stderr));
    let index = out.join("index.html");
    let html = std::fs::read_to_string(&index).unwrap();

    // Every linked file exists.
    let linked = links(&html);
    assert!(linked.len() > 10, "{linked:?}");
    for l in &linked {
        assert!(out.join(l).is_file(), "index.html links to {l}, which is not there");
    }
    let n_views = html.matches("<div class=\"view3d\"").count();
    assert_eq!(n_views, 2, "one 3-D view per case");

    // The page runs: no console message, no error caught by the page, every view drawn.
    let url = format!("file://{}", index.canonicalize().unwrap().display());
    let d = chrome(&exe, &dir, &url, &["--dump-dom"]);
    let dom = String::from_utf8_lossy(&d.stdout);
    let log = String::from_utf8_lossy(&d.stderr);
    assert!(d.status.success(), "{log}");
    let console: Vec<&str> = log.lines().filter(|l| l.contains("CONSOLE") || l.contains("Uncaught")).collect();
    assert!(console.is_empty(), "console messages:\n{}", console.join("\n"));
    // The page's own error handler marks the <html> element and fills #js-errors.
    let html_tag = dom.split("<html").nth(1).and_then(|s| s.split('>').next()).unwrap_or_default();
    assert!(!html_tag.contains("data-js-errors"), "the page caught errors: {}", &dom[..dom.len().min(3000)]);
    assert!(dom.contains("<div id=\"js-errors\" hidden=\"\"></div>"), "the page caught errors");
    assert!(html_tag.contains(&format!("data-views-drawn=\"{n_views}\"")), "not every view drew: <html{html_tag}>");
    let inked: Vec<usize> =
        dom.split("data-inked=\"").skip(1).map(|s| s.split('"').next().unwrap().parse().unwrap()).collect();
    assert_eq!(inked.len(), n_views);
    // A 880 × 440 canvas: the structure, wake and labels cover well over 500 pixels.
    assert!(inked.iter().all(|&n| n > 500), "inked pixels per view: {inked:?}");

    // A screenshot shows the drawing: the first view (the pendulum's) lies within 1800 px.
    let shot = |name: &str, url: &str| -> PathBuf {
        let p = dir.join(name);
        let args = ["--window-size=1400,1800".to_string(), format!("--screenshot={}", p.display())];
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = chrome(&exe, &dir, url, &refs);
        assert!(
            o.status.success() && p.is_file(),
            "{:?} {}: {}",
            o.status,
            p.display(),
            String::from_utf8_lossy(&o.stderr)
        );
        p
    };
    // The reference: the same page without its script (headless Chromium takes no screenshot
    // with scripts switched off), so the canvases stay empty.
    let start = html.rfind("<script>\n").expect("the viewer's script");
    let end = start + html[start..].find("</script>").unwrap() + "</script>".len();
    let bare = out.join("index-noscript.html");
    std::fs::write(&bare, format!("{}{}", &html[..start], &html[end..])).unwrap();
    let on = shot("on.png", &url);
    let off = shot("off.png", &format!("file://{}", bare.canonicalize().unwrap().display()));
    let c = Command::new(&py).args(["-c", COMPARE]).arg(&on).arg(&off).output().unwrap();
    let text = String::from_utf8_lossy(&c.stdout).to_string();
    assert!(c.status.success(), "{text}{}", String::from_utf8_lossy(&c.stderr));
    let v: Vec<usize> = text.split_whitespace().map(|x| x.parse().unwrap()).collect();
    eprintln!(
        "screenshot {} x {} px, {} bytes: {} pixels drawn by the scripts, {} of them in the formulations' colours",
        v[2],
        v[3],
        std::fs::metadata(&on).unwrap().len(),
        v[0],
        v[1]
    );
    assert_eq!((v[2], v[3]), (1400, 1800));
    assert!(v[1] > 300, "the 3-D view is blank in the screenshot: {text}");
    let _ = std::fs::remove_dir_all(&dir);
}
