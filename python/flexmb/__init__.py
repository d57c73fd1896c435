"""flexmb: nonlinear aeroelasticity of flared folding wingtips, from Python.

The same solvers as the ``harness`` command line (ANCF and GEBF beams, generalized-alpha, UVLM),
driven from a case file or a dict, with NumPy arrays back::

    import flexmb
    r = flexmb.run("cases/double_pendulum_c1_beta45.json", formulation="both", set={"t_end": 1.0})
    r["ancf"]["tip_z"]          # float64 array, one value per output row
    d = flexmb.tip_difference(r["ancf"], r["gebf"])

Arrays are keyed by the column names of the CLI's CSV files (``t``, ``tip_x``, ``tip_y``, ``tip_z``,
``fold``, ``kinetic``, ... ; docs/outputs.md section 2) and hold the unrounded ``float64`` values the
CLI formats into those files. A run releases the GIL and stops at the next time step on Ctrl-C
(``KeyboardInterrupt``). Errors in a case raise :class:`CaseError`, whose ``field`` is the path of
the offending value as the case file spells it.
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Mapping, Optional, Tuple, Union

import numpy as np

from . import _core
from ._core import CaseError, FlexmbError, RunError

__all__ = [
    "run",
    "sweep",
    "static",
    "stability",
    "trim",
    "tip_difference",
    "to_csv",
    "CaseError",
    "FlexmbError",
    "RunError",
    "__version__",
]

__version__: str = _core.__version__

CaseLike = Union[str, "os.PathLike[str]", Mapping[str, Any]]

_FORMULATIONS = {"ancf": ["ancf"], "gebf": ["gebf"], "both": ["ancf", "gebf"]}


def _source(case: CaseLike, base_dir: Optional[Union[str, "os.PathLike[str]"]]) -> Tuple[str, bool, str]:
    """(text or path, whether it is a path, folder references resolve against)."""
    if isinstance(case, Mapping):
        base = os.fspath(base_dir) if base_dir is not None else os.getcwd()
        return json.dumps(case), False, base
    if isinstance(case, (str, os.PathLike)):
        return os.fspath(case), True, ""
    raise TypeError(f"case: expected a path or a dict, not {type(case).__name__}")


def _overrides(set: Optional[Mapping[str, Any]]) -> list:
    """``{"t_end": 1.0, "gebf:joints.1.flare_deg": 40}`` as the CLI's ``--set path=value`` strings."""
    if not set:
        return []
    out = []
    for path, value in set.items():
        if not isinstance(path, str) or not path:
            raise TypeError(f"set: keys are case paths such as 't_end' or 'gebf:joints.1.flare_deg', not {path!r}")
        out.append(f"{path}={json.dumps(value)}")
    return out


def _formulations(formulation: str) -> list:
    try:
        return _FORMULATIONS[formulation]
    except (KeyError, TypeError):
        err = CaseError(f"formulation: {formulation!r} is not one of 'ancf', 'gebf', 'both'")
        err.field = "formulation"
        err.file = None
        raise err from None


def _shape(name: str, per: Dict[str, Tuple[Dict[str, np.ndarray], Optional[str]]], formulation: str, check: bool):
    for f, (cols, error) in per.items():
        if error is not None and check:
            err = RunError(f"{name} {f}: {error}")
            err.formulation = f
            err.result = cols
            err.run = name
            raise err
    if formulation == "both":
        return {f: cols for f, (cols, _) in per.items()}
    return per[formulation][0]


def _expand(fn, case, formulation, set, base_dir):
    text, is_path, base = _source(case, base_dir)
    return fn(text, is_path, base, _formulations(formulation), _overrides(set))


def run(
    case: CaseLike,
    formulation: str = "gebf",
    set: Optional[Mapping[str, Any]] = None,
    *,
    base_dir: Optional[Union[str, "os.PathLike[str]"]] = None,
    check: bool = True,
) -> Dict[str, Any]:
    """Run a case (one without a ``sweep``; see :func:`sweep`) and return its time history.

    Args:
        case: a case file's path, or the case as a dict (the JSON of a case file).
        formulation: ``"ancf"``, ``"gebf"`` or ``"both"``.
        set: overrides as ``harness --set`` takes them, ``{path: value}``, e.g.
            ``{"t_end": 1.0, "joints.1.flare_deg": 30, "gebf:gebf.dt": 1e-3}``.
        base_dir: for a dict, the folder its reference files are relative to (default: the
            current directory).
        check: raise :class:`RunError` when a run stops before its end time (its ``.result`` holds
            the rows until then); with ``False`` the partial arrays are returned.

    Returns:
        For one formulation, a dict of 1-D arrays keyed by the CLI CSV's column names (``t``,
        ``tip_x``, ``tip_y``, ``tip_z``, ``fold``, ``kinetic``, ``elastic``, ``potential``,
        [``spring``, ``dissipated``,] ``total``, [``aero_work``,] ``constraint_residual``,
        ``newton_iterations``[, ``lift``, ``root_bending_moment``, ``root_torque``,
        ``hinge_moment``]). For ``"both"``, ``{"ancf": {...}, "gebf": {...}}``.

    Raises:
        CaseError: the case or an override is invalid (``.field`` names the value).
        RunError: a run failed part-way (with ``check=True``).
        KeyboardInterrupt: Ctrl-C; the runs stop after their current step.
        OSError: the case file cannot be read.
    """
    runs = _expand(_core.run, case, formulation, set, base_dir)
    if len(runs) != 1:
        raise CaseError(
            f"sweep: the case expands into {len(runs)} runs; use flexmb.sweep() for a case with a sweep"
        )
    name, per = runs[0]
    return _shape(name, per, formulation, check)


def sweep(
    case: CaseLike,
    formulation: str = "gebf",
    set: Optional[Mapping[str, Any]] = None,
    *,
    base_dir: Optional[Union[str, "os.PathLike[str]"]] = None,
    check: bool = True,
) -> Dict[str, Dict[str, Any]]:
    """Run every point of a case's ``sweep`` (all of them in parallel); returns ``{run name: result}``
    with the run names of the CLI (``<name>__<key>=<value>...``) and each result as :func:`run`
    returns it. Arguments as for :func:`run`."""
    runs = _expand(_core.run, case, formulation, set, base_dir)
    return {name: _shape(name, per, formulation, check) for name, per in runs}


def static(
    case: CaseLike,
    formulation: str = "gebf",
    set: Optional[Mapping[str, Any]] = None,
    *,
    base_dir: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> Dict[str, Any]:
    """The static aeroelastic equilibria over the case's ``static.airspeeds`` (``harness static``).

    Returns a dict of arrays keyed by the columns of ``static_<formulation>.csv`` (``airspeed``,
    ``fold_deg``, ``tip_x``, ..., ``newton_iterations``, ``converged``; NaN where an airspeed has
    no equilibrium), or for ``"both"`` one such dict per formulation. A case with a ``sweep``
    returns ``{run name: ...}`` instead. Raises :class:`CaseError` when the case has no ``static``
    block and :class:`RunError` when a sweep could not start.
    """
    runs = _expand(_core.static_sweep, case, formulation, set, base_dir)
    shaped = {name: _shape(name, per, formulation, True) for name, per in runs}
    return next(iter(shaped.values())) if len(shaped) == 1 else shaped


def stability(
    case: CaseLike,
    formulation: str = "gebf",
    set: Optional[Mapping[str, Any]] = None,
    *,
    base_dir: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> Dict[str, Any]:
    """The linearised stability over the case's ``stability.airspeeds`` (``harness stability``:
    p-method flutter and divergence).

    Returns a dict of arrays keyed by the columns of ``stability_<formulation>.csv`` (one entry per
    airspeed and tracked mode: ``airspeed``, ``mode``, ``real``, ``imag``, ``frequency_hz``,
    ``frequency_rad_s``, ``damping_ratio``, ``converged``) plus ``summary``, a dict with
    ``flutter_speed``, ``flutter_frequency_rad_s``, ``flutter_mode`` and ``divergence_speed`` (None
    when the sweep finds none), and about a trim (``stability.about: "trim"``) ``flight_modes``: a
    list of dicts (``airspeed``, ``name`` such as ``"phugoid"``, ``real``, ``imag``, ``period_s``,
    ``damping_ratio``, ``symmetric``, ``rigid``) as ``flight_modes_<formulation>.csv``; for
    ``"both"`` one such dict per formulation, and for a case with a
    ``sweep`` ``{run name: ...}``. Raises :class:`CaseError` when the case has no ``stability``
    block and :class:`RunError` when the analysis could not start.
    """
    runs = _expand(_core.stability, case, formulation, set, base_dir)
    shaped = {name: _shape(name, per, formulation, True) for name, per in runs}
    return next(iter(shaped.values())) if len(shaped) == 1 else shaped


def trim(
    case: CaseLike,
    formulation: str = "gebf",
    set: Optional[Mapping[str, Any]] = None,
    *,
    base_dir: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> Dict[str, Any]:
    """The level-flight trim of a free aircraft (``harness trim``, the case's ``trim`` block).

    Returns a dict as ``trim_<formulation>.json``: ``alpha_deg``, ``controls`` (name -> deg),
    ``thrust`` (N), ``residuals`` (``force_forward``, ``force_up``, ``pitch_moment``),
    ``converged``, ``error``, ``lift``, ``drag``, ``tip``, ``iterations``, ``static_solves``,
    ``wall_s`` and ``q`` (the deformed state, a NumPy array); for ``"both"`` one such dict per
    formulation, and for a case with a ``sweep`` ``{run name: ...}``. Raises :class:`CaseError`
    when the case has no ``trim`` block or cannot be trimmed, :class:`RunError` when a trim
    failed to converge.
    """
    runs = _expand(_core.trim, case, formulation, set, base_dir)

    def one(name: str, f: str, text: str, err: Optional[str]) -> Dict[str, Any]:
        if err is not None:
            raise RunError(f"{name} {f}: {err}")
        d = json.loads(text)
        d["controls"] = {n: v for n, v in d["controls"]}
        d["q"] = np.asarray(d["q"], dtype=float)
        return d

    shaped = {}
    for name, per in runs:
        out = {f: one(name, f, text, err) for f, (text, err) in per.items()}
        shaped[name] = out if formulation == "both" else out[formulation]
    return next(iter(shaped.values())) if len(shaped) == 1 else shaped


def tip_difference(a: Mapping[str, np.ndarray], b: Mapping[str, np.ndarray]) -> Tuple[np.ndarray, np.ndarray]:
    """The tip distance ``|tip_a(t) - tip_b(t)|`` (m) at the times of ``a``, ``b`` interpolated
    linearly, exactly as the CLI computes its ANCF-GEBF tip difference: ``d.max()`` is the
    ``tip_difference.all.max`` of the CLI's ``summary.json``. Returns ``(t, d)``."""
    t, d = _core.tip_difference(dict(a), dict(b))
    return np.asarray(t), np.asarray(d)


def to_csv(result: Mapping[str, np.ndarray]) -> str:
    """The CSV text the CLI writes for a run with these arrays (``<formulation>.csv``), byte for byte."""
    return _core.to_csv(dict(result))
