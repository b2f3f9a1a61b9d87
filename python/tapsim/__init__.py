"""tapsim from Python: tapping-mode AFM with adhesion hysteresis done right.

Every function runs the tapsim command of the same name in this process -- the same
parsing, defaults, checks and numbers as ``tapsim <command> --json`` -- with the GIL
released, and returns a :class:`Result`. Keyword arguments are the command line's
flags in snake case (``sample_modulus`` for ``--sample-modulus``), with the same
defaults; values are SI floats (``20e-9``) or strings with units (``"20nm"``,
``"0.5GPa"``, ``"50mJ/m^2"``); ``True`` gives a bare flag, a list repeats the flag.
Bad input raises ``ValueError`` with the message the command line prints.

Quick start::

    import tapsim
    r = tapsim.tap()                        # the built-in defaults
    r.amplitude_ratio, r.phase_deg, r.e_ts_j
    c = tapsim.approach(points=40)          # columns as numpy arrays
    m = tapsim.map(steps=10)                # m.grid["phase_deg"] is a 2-D array

See ``help(tapsim.Result)`` and the README's "Python" section.
"""

from __future__ import annotations

import copy as _copy
import os as _os
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence

import numpy as _np

from . import _tapsim

__version__ = _tapsim.__version__

__all__ = [
    "Result",
    "Setup",
    "tap",
    "approach",
    "branches",
    "bifurcation",
    "contrast",
    "map",
    "scan",
    "thermal",
    "peakforce",
    "force_curve",
    "hysteresis",
    "lj",
    "fit",
    "reconstruct",
    "tap_many",
    "model",
]


class Result:
    """One command's ``--json`` document.

    Its keys are attributes (``r.phase_deg``, ``r.e_ts_j``; units are the key's
    suffix: ``_m``, ``_j``, ``_deg``, ``_hz``, ``_pa``; ``_hat`` keys are the paper's
    dimensionless quantities). A column of numbers is a numpy array (float64 with the
    command line's exact bits, int64 where every entry is an integer); one with gaps
    (``null`` in the JSON: no steady state on that branch, a law that does not apply)
    a masked array; a column of names or flags a numpy array of str or bool; a map's
    grid is a 2-D array, row per value of the slow axis.
    ``to_dict()`` gives the whole document.
    """

    __slots__ = ("command", "_data")

    def __init__(self, command: str, data: Dict[str, Any]):
        self.command = command
        self._data = {k: _modes(v) if k == "modes" else _arrays(v) for k, v in data.items()}

    def __getattr__(self, key: str) -> Any:
        try:
            return self._data[key]
        except KeyError:
            raise AttributeError(
                f"tapsim {self.command} has no {key!r} (its keys: {', '.join(self._data)})"
            ) from None

    def __getitem__(self, key: str) -> Any:
        return self._data[key]

    def __contains__(self, key: str) -> bool:
        return key in self._data

    def __dir__(self) -> List[str]:
        return sorted(set(self._data) | {"command", "keys", "to_dict"})

    def keys(self) -> List[str]:
        """The document's keys, in the command's order."""
        return list(self._data)

    def to_dict(self) -> Dict[str, Any]:
        """The whole document as a dict (numpy arrays for columns and grids)."""
        return dict(self._data)

    def __repr__(self) -> str:
        scalar = [
            k for k, v in self._data.items()
            if k != "format_version" and not isinstance(v, (list, dict, _np.ndarray))
        ]
        preferred = ("law", "amplitude_ratio", "phase_deg", "e_ts_j", "w_hat", "regime")
        keys = [k for k in preferred if k in scalar] or scalar[:4]
        shown = ", ".join(f"{k}={self._data[k]!r}" for k in keys)
        more = len(self._data) - len(keys)
        return f"<tapsim {self.command}: {shown or 'columns'} (+{more} keys)>"


def _arrays(value: Any) -> Any:
    """A list of numbers with gaps (None), 1-D or rows of one length, as a masked
    array; dicts inside converted too; anything else as it is."""
    if isinstance(value, dict):
        return {k: _arrays(v) for k, v in value.items()}
    if not (isinstance(value, list) and value):
        return value
    if all(isinstance(x, str) for x in value) or all(isinstance(x, bool) for x in value):
        # A column of names or flags: an array, for masks such as `r.branch == "repulsive"`.
        return _np.array(value)
    rows = all(isinstance(row, list) for row in value)
    if rows and len({len(row) for row in value}) != 1:
        return value
    flat = [x for row in value for x in row] if rows else value
    numbers = [x for x in flat if x is not None]
    if not numbers or len(numbers) == len(flat):
        return value
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in numbers):
        return value
    data = _np.array([_np.nan if x is None else x for x in flat], dtype=float)
    mask = _np.array([x is None for x in flat])
    if rows:
        data, mask = data.reshape(len(value), -1), mask.reshape(len(value), -1)
    return _np.ma.masked_array(data, mask=mask)


def _modes(value: Any) -> Any:
    """A several-mode state's `modes` (one object per mode) as columns, like a sweep's:
    ``r.modes.phase_deg[1]`` is the second mode's phase. A scan's (per pixel, one object
    per higher mode) as 2-D columns: ``r.modes.phase_deg[i, 0]`` is pixel i's φ₂."""
    if not (isinstance(value, list) and value):
        return _arrays(value)
    if all(isinstance(x, dict) for x in value):
        return Result("modes", {k: _column([x[k] for x in value]) for k in value[0]})
    rows = [x for x in value if isinstance(x, list)]
    if (
        len(rows) == len(value)
        and rows[0]
        and all(len(r) == len(rows[0]) and all(isinstance(m, dict) for m in r) for r in rows)
    ):
        keys = rows[0][0]
        return Result(
            "modes",
            {k: _np.array([[m[k] for m in r] for r in rows]) for k in keys},
        )
    return _arrays(value)


def _column(values: List[Any]) -> Any:
    """A column of one object list: float64 (or int64) where every entry is a number,
    as `_arrays` does otherwise."""
    if all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in values):
        kind = _np.int64 if all(isinstance(x, int) for x in values) else _np.float64
        return _np.array(values, dtype=kind)
    return _arrays(values)


def _flag(key: str) -> str:
    # A trailing underscore lets a flag that is a Python keyword through (``from_``).
    return "--" + key.rstrip("_").replace("_", "-")


def _text(value: Any) -> str:
    if isinstance(value, bool):
        raise TypeError("a bool is a bare flag")
    if isinstance(value, (float, _np.floating)):
        # repr is the shortest text that reads back as the same float: the command line
        # gets exactly this number.
        return repr(float(value))
    if isinstance(value, (int, _np.integer)):
        return str(int(value))
    if isinstance(value, str):
        return value
    raise TypeError(f"{value!r} is not a number or a string")


def _argv(command: str, options: Dict[str, Any]) -> List[str]:
    """The command line for ``command`` with these keyword arguments, as JSON."""
    args = [command]
    for key, value in options.items():
        if value is None or value is False:
            continue
        flag = _flag(key)
        if value is True:
            args.append(flag)
        elif isinstance(value, (list, tuple, _np.ndarray)):
            for item in value:
                args.append(f"{flag}={_text(item)}")
        else:
            args.append(f"{flag}={_text(value)}")
    return args + ["--json", "--quiet"]


class Setup:
    """A set of keyword arguments to reuse and vary: ``Setup(law="jkr",
    separation="14nm")``; ``s.replace(separation="12nm")`` is a new Setup with that
    changed (None removes a key); ``tapsim.tap(s)`` or ``tapsim.tap(s, plot=...)``
    (call arguments win); ``tapsim.tap_many([s1, s2, ...])`` runs many in parallel."""

    __slots__ = ("_options",)

    def __init__(self, **options: Any):
        self._options = dict(options)

    def replace(self, **changes: Any) -> "Setup":
        options = dict(self._options)
        for key, value in changes.items():
            if value is None:
                options.pop(key, None)
            else:
                options[key] = value
        return Setup(**options)

    def copy(self) -> "Setup":
        return Setup(**_copy.deepcopy(self._options))

    def to_dict(self) -> Dict[str, Any]:
        return dict(self._options)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Setup) and other._options == self._options

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}={v!r}" for k, v in self._options.items())
        return f"Setup({inner})"


def _options(setup: Optional[Setup], kwargs: Dict[str, Any]) -> Dict[str, Any]:
    if setup is not None and not isinstance(setup, Setup):
        raise TypeError(f"the first argument is a tapsim.Setup, not {type(setup).__name__}")
    options = setup.to_dict() if setup is not None else {}
    options.update(kwargs)
    return options


def _run(command: str, setup: Optional[Setup], kwargs: Dict[str, Any]) -> Result:
    return Result(command, _tapsim.run(_argv(command, _options(setup, kwargs))))


def tap(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """A cantilever tapping against a force law, to its steady state (``tapsim tap``):
    amplitude A/A0, phase phi, energy dissipated per cycle E_ts, regime (period-n or
    irregular), Floquet multipliers, harmonics, grazing margin; with ``setpoint=0.8``
    every stable state at that amplitude setpoint (``states``)."""
    return _run("tap", setup, kwargs)


def approach(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """An approach-retract curve (``tapsim approach``): one entry per rest separation
    (or setpoint with ``sweep="setpoint"``) in every column."""
    return _run("approach", setup, kwargs)


def branches(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """The period-1 orbit families through the rest separation (``tapsim branches``)."""
    return _run("branches", setup, kwargs)


def bifurcation(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """A bifurcation diagram over the rest separation (``tapsim bifurcation``)."""
    return _run("bifurcation", setup, kwargs)


def contrast(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """Phase contrast between materials at amplitude setpoints (``tapsim contrast``):
    one entry per law, setpoint and branch; per-material columns are 2-D."""
    return _run("contrast", setup, kwargs)


def map(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:  # noqa: A001
    """Maps over (work of adhesion, composite modulus) (``tapsim map``): the axes
    ``work_of_adhesion_j_m2`` and ``modulus_pa``, and ``grid`` with one 2-D array per
    observable (rows: modulus; columns: work of adhesion)."""
    return _run("map", setup, kwargs)


def scan(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """A line scan (or image) with the z feedback closed (``tapsim scan``)."""
    return _run("scan", setup, kwargs)


def thermal(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """The free cantilever's thermal noise and its spectrum fit (``tapsim thermal``)."""
    return _run("thermal", setup, kwargs)


def peakforce(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """Off-resonance tapping, PeakForce-type (``tapsim peakforce``): one settled cycle
    at a peak-force setpoint (``peak_force="5nN"``, the default) or a separation, and
    its QNM channels per cycle (``cycles``: peak force, adhesion, dissipation,
    deformation, DMT modulus); ``curve=True`` adds the recorded force curve as numpy
    arrays (``curve["force_n"]`` against ``curve["separation_m"]`` or ``curve["t_s"]``)."""
    return _run("peakforce", setup, kwargs)


def force_curve(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """A force-distance curve (``tapsim force-curve``): the support ramped from
    ``from_="20nm"`` toward the sample at ``velocity="1um/s"``, turned at the trigger
    (``trigger="5nN"``) or at ``to``, held for ``dwell`` and withdrawn; the snap-in and
    pull-off (``snap_in``, ``pull_off``: piezo position, tip separation, force), the QNM
    channels of the curve (``channels``), the energy books, and with ``curve=True`` the
    curve as numpy arrays (``curve["force_n"]`` against ``curve["piezo_m"]``,
    ``curve["separation_m"]`` or ``curve["t_s"]``; at most ``points`` of them)."""
    return _run("force-curve", setup, kwargs)


def hysteresis(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """The closed-form hysteresis of one contact (``tapsim hysteresis``): JKR (9), the
    hybrid (18), the finite-stiffness loss (26)."""
    return _run("hysteresis", setup, kwargs)


def lj(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """The Lennard-Jones solution at a Tabor parameter (``tapsim lj``, mu required):
    the folds A and C, W_LJ with its error estimate."""
    return _run("lj", setup, kwargs)


def fit(data: Any, setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """A measured approach curve (a CSV path: position, amplitude and/or phase columns
    with units in the header, as ``tapsim fit`` reads it) fitted by the simulator
    (``tapsim fit``): ``parameters`` (value, std_err, interval_68, interval_95,
    identifiable), ``identifiability`` (singular_values, condition_number, correlations,
    notes), chi_square, ``converged``, ``diagnosis`` (describes_data, reasons,
    worst_points), the ``minima`` found, the fitted curve; ``profile=True`` adds
    ``profiles``. ``law=["hybrid", "jkr"]`` fits each law: ``laws`` (one report per
    law) and ``comparison`` (ranking by AIC and BIC, ``verdict`` in words)."""
    args = _argv("fit", _options(setup, kwargs))
    return Result("fit", _tapsim.run([args[0], _os.fspath(data)] + args[1:]))


def reconstruct(data: Any, setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """The force and the loss an AM curve implies (``tapsim reconstruct``; a CSV path
    with position, amplitude and phase columns, units in the header, as ``tapsim
    approach --csv`` writes it): columns closest_m, force_n, e_ts_j, in_phase_force_n,
    frequency_shift (with ``with_law=True`` also law_approach_force_n and
    law_retract_force_n), and notes."""
    args = _argv("reconstruct", _options(setup, kwargs))
    return Result("reconstruct", _tapsim.run([args[0], _os.fspath(data)] + args[1:]))


def tap_many(setups: Iterable[Setup], /, **common: Any) -> List[Result]:
    """``tap`` for every setup, in parallel on all cores (the GIL released), in order;
    ``common`` keyword arguments apply to each (a setup's own win)."""
    batch = []
    for s in setups:
        options = dict(common)
        options.update(_options(s, {}))
        batch.append(_argv("tap", options))
    return [Result("tap", d) for d in _tapsim.run_many(batch)]


def model(
    parameters: Sequence[str],
    outputs: Sequence[str] = ("amplitude_ratio", "phase_deg"),
    setup: Optional[Setup] = None,
    **fixed: Any,
) -> Callable[..., "_np.ndarray"]:
    """A function of the named parameters (SI floats) returning the named outputs of
    ``tap`` as a float array, for your own fits (scipy.optimize.least_squares,
    curve_fit): ``f = tapsim.model(["sample_modulus", "work_of_adhesion"],
    setpoint=0.8)``; ``f(1e9, 0.08)`` -> ``array([A/A0, phi])``. With a setpoint, the
    first state listed (the attractive one where both exist; ``branch=`` picks)."""
    names = list(parameters)
    wanted = list(outputs)
    base = _options(setup, fixed)

    def evaluate(*values: float) -> "_np.ndarray":
        if len(values) != len(names):
            raise TypeError(f"expected {len(names)} values ({', '.join(names)}), got {len(values)}")
        options = dict(base)
        options.update({n: float(v) for n, v in zip(names, values)})
        r = tap(**options)
        return _np.array([float(r[k]) for k in wanted])

    evaluate.__doc__ = f"tapsim tap -> {wanted} as a function of {names}"
    return evaluate
