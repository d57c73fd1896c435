"""flexmb against the harness command line, its errors, the GIL and Ctrl-C."""

import io
import json
import os
import pathlib
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import flexmb
from conftest import PENDULUM, ROOT


def _csv(text: str) -> np.ndarray:
    return np.loadtxt(io.StringIO(text), delimiter=",", skiprows=1)


def test_pendulum_equals_the_cli_bitwise(harness_bin, tmp_out):
    """The paper's c = 1, beta = 45 deg pendulum, both formulations.

    "Bitwise" here: the arrays flexmb returns are the unrounded f64 values of the rows the CLI
    formats into its CSV files. Checked three ways: (1) the CLI's own CSV writer applied to the
    Python arrays (flexmb.to_csv) gives the CLI's ancf.csv and gebf.csv byte for byte; (2) the
    CLI's CSV files parse into arrays np.array_equal to the Python arrays rounded the same way;
    (3) the maximum of the ANCF-GEBF tip distance computed from the Python arrays equals, as an
    f64, the CLI's summary.json tip_difference.all.max (written with full round-trip precision),
    and the example script prints the CLI's line."""
    cli = subprocess.run(
        [str(harness_bin), "run", str(PENDULUM), "--out", str(tmp_out)],
        capture_output=True, text=True, cwd=ROOT, check=True,
    )
    folder = tmp_out / "double_pendulum_c1_beta45"
    r = flexmb.run(PENDULUM, formulation="both")
    assert set(r) == {"ancf", "gebf"}
    for f in ("ancf", "gebf"):
        text = (folder / f"{f}.csv").read_text()
        assert list(r[f]) == text.splitlines()[0].split(",")
        assert flexmb.to_csv(r[f]) == text
        assert np.array_equal(_csv(text), _csv(flexmb.to_csv(r[f])))
        assert r[f]["t"].dtype == np.float64 and r[f]["newton_iterations"].dtype == np.int64
    _, d = flexmb.tip_difference(r["ancf"], r["gebf"])
    summary = json.loads((folder / "summary.json").read_text())
    assert float(d.max()) == summary["tip_difference"]["all"]["max"]
    line = next(l for l in cli.stdout.splitlines() if "max tip difference" in l)
    ex = subprocess.run(
        [sys.executable, str(ROOT / "python" / "examples" / "pendulum.py"), str(PENDULUM)],
        capture_output=True, text=True, check=True,
    )
    assert line.split(": ", 1)[1] in ex.stdout, (line, ex.stdout)


def test_case_from_a_dict_with_overrides():
    case = json.loads(PENDULUM.read_text())
    a = flexmb.run(case, "gebf", set={"t_end": 0.1}, base_dir=PENDULUM.parent)
    b = flexmb.run(PENDULUM, "gebf", set={"t_end": 0.1})
    assert a["t"][-1] == pytest.approx(0.1)
    for k in a:
        assert np.array_equal(a[k], b[k]), k
    # A formulation-specific override only changes that formulation.
    c = flexmb.run(PENDULUM, "both", set={"t_end": 0.1, "gebf:joints.1.flare_deg": 30})
    assert np.array_equal(c["ancf"]["tip_z"], flexmb.run(PENDULUM, "ancf", set={"t_end": 0.1})["tip_z"])
    assert not np.array_equal(c["gebf"]["tip_z"], b["tip_z"])


def test_a_sweep_runs_every_point():
    case = json.loads(PENDULUM.read_text())
    case["sweep"] = [{"path": "joints.1.flare_deg", "values": [0, 45]}]
    case["references"] = []
    r = flexmb.sweep(case, "ancf", set={"t_end": 0.05})
    assert list(r) == ["double_pendulum_c1_beta45__flare_deg=0", "double_pendulum_c1_beta45__flare_deg=45"]
    with pytest.raises(flexmb.CaseError, match="flexmb.sweep"):
        flexmb.run(case, "ancf", set={"t_end": 0.05})


@pytest.mark.parametrize(
    "set_, field",
    [
        ({"ancf.dt": -1}, "ancf.dt"),
        ({"bodies.1.length": -0.5}, "bodies[1].length"),
        ({"t_ned": 1.0}, "t_ned"),
        ({"gebf.dtt": 1e-3}, "gebf.dtt"),
        ({"joints.7.flare_deg": 1}, "joints.7"),
    ],
)
def test_case_errors_carry_the_field(set_, field):
    with pytest.raises(flexmb.CaseError) as e:
        flexmb.run(PENDULUM, "gebf", set=set_)
    assert e.value.field == field, str(e.value)
    assert isinstance(e.value, flexmb.FlexmbError)


def test_other_errors():
    with pytest.raises(flexmb.CaseError) as e:
        flexmb.run(PENDULUM, formulation="euler")
    assert e.value.field == "formulation"
    with pytest.raises(OSError):
        flexmb.run(ROOT / "cases" / "no_such_case.json")
    with pytest.raises(TypeError):
        flexmb.run(42)
    with pytest.raises(flexmb.CaseError) as e:
        flexmb.static(PENDULUM)
    assert e.value.field == "static"


def test_static_sweep_columns():
    case = ROOT / "cases" / "healy_ffwt_flare10_aoa0.json"
    r = flexmb.static(case, "gebf", set={"static.airspeeds": [15, 25]})
    header = "airspeed,fold_deg,tip_x,tip_y,tip_z,root_bending_moment,root_torque,hinge_moment,lift," \
        "root_force_x,root_force_y,root_force_z,root_moment_x,root_moment_y,root_moment_z,newton_iterations,converged,drag,sideslip_deg," \
        "profile_drag,induced_drag"
    assert list(r) == header.split(",")
    assert np.array_equal(r["profile_drag"], [0.0, 0.0])
    assert np.allclose(r["induced_drag"], r["drag"], rtol=0, atol=0)
    assert np.array_equal(r["airspeed"], [15.0, 25.0])
    assert r["converged"].all() and np.all(r["lift"] > 0)


def test_a_run_releases_the_gil():
    """Python code runs on another thread while a run computes."""
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.002)

    t = threading.Thread(target=tick)
    t.start()
    t0 = time.perf_counter()
    flexmb.run(PENDULUM, "gebf")
    t1 = time.perf_counter()
    stop.set()
    t.join()
    during = [x for x in ticks if t0 < x < t1]
    assert len(during) >= 0.25 * (t1 - t0) / 0.002, (len(during), t1 - t0)


def test_ctrl_c_stops_a_long_run_and_the_next_run_works():
    """SIGINT during a 400 s simulated run: KeyboardInterrupt within a second, and the harness's
    stop flag is cleared so that the next run reaches its end. The run takes steps of 0.1 ms so
    that even a fast machine is still in its first seconds of simulated time when the signal
    arrives (at the case's 2 ms GEBF stops near t = 7 s, which an idle machine reaches in 0.5 s).
    The script installs Python's SIGINT handler itself, since CI may start it with SIGINT ignored.
    The run must stop within 1.5 s."""
    script = f"""
import os, signal, sys, threading, time
import flexmb
case = {str(PENDULUM)!r}
# Python answers SIGINT only with its own handler installed; a process started with SIGINT
# ignored (a background job of a non-interactive shell, as CI scripts often are) inherits the
# "ignore" and would never see the Ctrl-C below.
signal.signal(signal.SIGINT, signal.default_int_handler)
threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
t0 = time.perf_counter()
try:
    flexmb.run(case, "gebf", set={{"t_end": 400, "gebf.dt": 1e-4, "output_dt": 0.01}})
    print("not interrupted")
except KeyboardInterrupt:
    print(f"interrupted after {{time.perf_counter() - t0:.2f}} s")
r = flexmb.run(case, "gebf", set={{"t_end": 0.1}})
print(f"next run to t = {{r['t'][-1]:.3f}}")
"""
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    assert lines[0].startswith("interrupted after"), p.stdout
    assert float(lines[0].split()[2]) < 1.5, p.stdout
    assert lines[1] == "next run to t = 0.100", p.stdout


def test_a_failed_run_raises_with_the_rows_so_far():
    # One Newton iteration per step cannot meet a 1e-14 tolerance: the first step fails.
    bad = {"gebf.newton.max_iter": 1, "gebf.newton.rtol": 1e-14, "gebf.newton.atol": 1e-14, "t_end": 0.1}
    with pytest.raises(flexmb.RunError) as e:
        flexmb.run(PENDULUM, "gebf", set=bad)
    assert e.value.formulation == "gebf"
    assert "t" in e.value.result
    partial = flexmb.run(PENDULUM, "gebf", set=bad, check=False)
    assert np.array_equal(partial["t"], e.value.result["t"])


def test_stability_sweep_columns():
    case = ROOT / "cases" / "goland_flutter.json"
    r = flexmb.stability(case, "gebf", set={"stability.airspeeds": [140, 190]})
    cols = "airspeed,mode,real,imag,frequency_hz,frequency_rad_s,damping_ratio,converged".split(",")
    assert [k for k in r if k != "summary"] == cols
    assert set(np.unique(r["airspeed"])) <= {140.0, 190.0}
    assert set(r["summary"]) == {"flutter_speed", "flutter_frequency_rad_s", "flutter_mode", "divergence_speed"}
    with pytest.raises(flexmb.CaseError) as e:
        flexmb.stability(PENDULUM)
    assert e.value.field == "stability"


def test_flight_modes_of_the_horten_wing_about_trim():
    """flexmb.stability about a trim gives the free aircraft's phugoid: SHARPy's 20.7 s within 10 %."""
    r = flexmb.stability(ROOT / "cases" / "flight" / "horten_level_flight.json", "gebf", set={"stability.airspeeds": [30]})
    modes = {m["name"]: m for m in r["summary"]["flight_modes"]}
    assert {"phugoid", "short_period", "dutch_roll", "roll_subsidence", "spiral"} <= set(modes)
    assert abs(modes["phugoid"]["period_s"] - 20.7) < 0.1 * 20.7


def test_trim_of_the_horten_wing():
    """flexmb.trim gives harness trim's trimmed state: SHARPy's alpha within 0.1 deg."""
    r = flexmb.trim(ROOT / "cases" / "horten_flying_wing.json", "gebf")
    assert r["converged"] and r["error"] is None
    assert abs(r["alpha_deg"] - 4.5135) < 0.1
    assert set(r["controls"]) == {f"elevon_r{k}" for k in range(5, 11)}
    assert r["thrust"] > 0 and r["q"].ndim == 1 and r["q"].size > 100
    with pytest.raises(flexmb.CaseError) as e:
        flexmb.trim(PENDULUM)
    assert e.value.field == "trim"
