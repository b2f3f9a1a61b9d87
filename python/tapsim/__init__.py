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

See ``help(tapsim.Result)`` and the guide's Python page (docs/src/how-to/python.md).
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
    "fm",
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
        return sorted(set(self._data) | {"command", "keys", "to_dict", "to_pandas", "to_xarray"})

    def keys(self) -> List[str]:
        """The document's keys, in the command's order."""
        return list(self._data)

    def to_dict(self) -> Dict[str, Any]:
        """The whole document as a dict (numpy arrays for columns and grids)."""
        return dict(self._data)

    def _scalars(self) -> Dict[str, Any]:
        return {
            k: v for k, v in self._data.items()
            if isinstance(v, (str, int, float, bool)) and not isinstance(v, _np.ndarray)
        }

    def _table(self) -> Dict[str, Any]:
        """One column per key, one entry per point (cell of a map, pixel of a scan,
        setpoint of a sweep); gaps as NaN."""
        d = self._data
        if isinstance(d.get("grid"), dict) and "work_of_adhesion_j_m2" in d:
            works = _np.asarray(d["work_of_adhesion_j_m2"], dtype=float)
            moduli = _np.asarray(d["modulus_pa"], dtype=float)
            table = {
                "work_of_adhesion_j_m2": _np.tile(works, len(moduli)),
                "modulus_pa": _np.repeat(moduli, len(works)),
            }
            shape = (len(moduli), len(works))
            for k, v in d["grid"].items():
                a = _grid(v, shape)
                if a is None:
                    try:
                        a = _np.asarray(v)
                    except ValueError:
                        continue
                    if a.shape != shape:
                        continue
                if k not in table:
                    table[k] = a.reshape(-1)
            return table
        columns = {
            k: v for k, v in d.items()
            if isinstance(v, _np.ndarray) and v.ndim == 1 and v.size > 0
        }
        if not columns:
            raise ValueError(f"tapsim {self.command} has no columns to tabulate (its keys: {', '.join(d)})")
        lengths = [len(v) for v in columns.values()]
        n = max(set(lengths), key=lengths.count)
        table = {
            k: (_np.ma.filled(v.astype(float), _np.nan) if _np.ma.isMaskedArray(v) else v)
            for k, v in columns.items() if len(v) == n
        }
        modes = d.get("modes")
        if isinstance(modes, Result):
            for k, v in modes._data.items():
                a = _np.asarray(v)
                if a.ndim == 2 and a.shape[0] == n:
                    for i in range(a.shape[1]):
                        table[f"modes_{i + 1}_{k}"] = a[:, i]
        return table

    def to_pandas(self) -> Any:
        """The result as a pandas DataFrame: one row per point (a sweep's setpoint, a
        map's cell, a scan's pixel), the JSON's keys as columns with the units in their
        names, gaps as NaN; the scalar keys (law, ...) in ``df.attrs``. Needs pandas."""
        import pandas as pd

        df = pd.DataFrame(self._table())
        df.attrs.update(self._scalars())
        df.attrs["command"] = self.command
        return df

    def to_xarray(self) -> Any:
        """The result as an xarray Dataset with labelled axes in SI: a map over
        (modulus_pa, work_of_adhesion_j_m2); a scanned image over (direction, y_m, x_m),
        x ascending in both directions; anything else over its points. The scalar keys
        as attributes. Needs xarray."""
        import xarray as xr

        d = self._data
        attrs = dict(self._scalars(), command=self.command)
        if isinstance(d.get("grid"), dict) and "work_of_adhesion_j_m2" in d:
            coords = {
                "modulus_pa": _np.asarray(d["modulus_pa"], dtype=float),
                "work_of_adhesion_j_m2": _np.asarray(d["work_of_adhesion_j_m2"], dtype=float),
            }
            shape = (len(coords["modulus_pa"]), len(coords["work_of_adhesion_j_m2"]))
            data = {}
            for k, v in d["grid"].items():
                a = _grid(v, shape)
                if a is not None and k not in coords:
                    data[k] = (("modulus_pa", "work_of_adhesion_j_m2"), a)
            return xr.Dataset(data, coords=coords, attrs=attrs)
        table = self._table()
        if {"direction", "line", "x_m", "y_m"} <= set(table):
            directions = [x for x in ("trace", "retrace") if _np.any(table["direction"] == x)]
            lines = int(_np.max(table["line"])) + 1
            ys = _np.array([table["y_m"][table["line"] == j][0] for j in range(lines)])
            xs = _np.sort(_np.unique(table["x_m"][table["direction"] == directions[0]]))
            data = {}
            for k, v in table.items():
                if k in ("direction", "line", "x_m", "y_m") or not _is_numeric(v):
                    continue
                grid = _np.full((len(directions), lines, len(xs)), _np.nan)
                for a, direction in enumerate(directions):
                    for j in range(lines):
                        mine = (table["direction"] == direction) & (table["line"] == j)
                        order = _np.argsort(table["x_m"][mine])
                        grid[a, j, :] = _np.asarray(v, dtype=float)[mine][order]
                data[k] = (("direction", "y_m", "x_m"), grid)
            coords = {"direction": directions, "y_m": ys, "x_m": xs}
            return xr.Dataset(data, coords=coords, attrs=attrs)
        return xr.Dataset({k: ("point", v) for k, v in table.items()}, attrs=attrs)

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


def _grid(value: Any, shape: Any) -> Optional[Any]:
    """A map grid's entry as a float array of `shape` (gaps NaN), or None where it is
    not one number per cell (names, flags, lists per cell)."""
    if _np.ma.isMaskedArray(value):
        value = _np.ma.filled(value.astype(float), _np.nan)
    try:
        a = _np.asarray(value)
    except ValueError:
        return None
    if a.shape != tuple(shape):
        return None
    if a.dtype.kind in "fiu":
        return a.astype(float)
    if a.dtype == object and all(
        x is None or (isinstance(x, (int, float)) and not isinstance(x, bool)) for x in a.ravel()
    ):
        return _np.array([_np.nan if x is None else x for x in a.ravel()], dtype=float).reshape(shape)
    return None


def _is_numeric(value: Any) -> bool:
    return _np.asarray(value).dtype.kind in "fiub" and _np.asarray(value).dtype.kind != "b"


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
        """A new Setup with ``changes`` applied (a value of None removes the key)."""
        options = dict(self._options)
        for key, value in changes.items():
            if value is None:
                options.pop(key, None)
            else:
                options[key] = value
        return Setup(**options)

    def copy(self) -> "Setup":
        """A deep copy (list values included)."""
        return Setup(**_copy.deepcopy(self._options))

    def to_dict(self) -> Dict[str, Any]:
        """The keyword arguments as a dict."""
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


def fm(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """An FM-AFM approach at constant amplitude (``tapsim fm``): the loops settled (drive
    90 degrees ahead, amplitude held at the free amplitude), from ``from_`` to ``to``
    in ``points`` points; per point the frequency shift ``frequency_shift_hz``, the
    excitation ``excitation_ratio`` (F/F0) and the energy it reads per cycle
    ``e_ts_from_excitation_j``, beside the law's own loss ``loop_loss_j``, ``grazing``
    and, where the loops find no orbit, a ``note``. ``to_pandas()`` gives one row a
    point."""
    return _run("fm", setup, kwargs)


def hysteresis(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """The closed-form hysteresis of one contact (``tapsim hysteresis``): JKR (9), the
    hybrid (18), the finite-stiffness loss (26)."""
    return _run("hysteresis", setup, kwargs)


def lj(setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """The Lennard-Jones solution at a Tabor parameter (``tapsim lj``, mu required):
    the folds A and C, W_LJ with its error estimate."""
    return _run("lj", setup, kwargs)


# Data columns as the CSV reader names them (units in the name), and the short
# keywords in SI: z and amplitude in m, phase in degrees.
_DATA_COLUMNS = {
    f"{p}_{u}" for p in ("z", "z_c", "separation", "position") for u in ("m", "nm")
} | {
    "amplitude_m", "amplitude_nm", "amplitude_ratio", "amplitude_v",
    "amplitude1_m", "amplitude1_nm", "amplitude1_ratio", "amplitude1_v",
    "phase_deg", "phase1_deg", "amplitude2_m", "amplitude2_nm", "amplitude2_ratio",
    "phase2_deg", "setpoint_ratio", "deflection_m", "deflection_nm", "mean_force_n",
    "frequency_shift_hz", "df_hz", "excitation_ratio",
}
_DATA_ALIASES = {
    "z": "z_m", "amplitude": "amplitude_m", "phase": "phase_deg",
    "amplitude2": "amplitude2_m", "phase2": "phase2_deg", "deflection": "deflection_m",
}
# Columns of labels (a DataFrame's or a dict's; as keywords they would be flags).
_LABEL_COLUMNS = {"direction", "segment"}
_POSITIONS = sorted(c for c in _DATA_COLUMNS if c.split("_")[0] in ("z", "separation", "position"))


def _data_columns(data: Any, kwargs: Dict[str, Any]) -> Optional[Dict[str, Any]]:
    """The curve's columns given as arrays -- a pandas DataFrame or a dict as ``data``,
    or keywords -- by their CSV names; None where ``data`` is a path."""
    is_path = isinstance(data, (str, bytes, _os.PathLike))
    columns: Dict[str, Any] = {}
    if data is not None and not is_path:
        if hasattr(data, "columns") and hasattr(data, "__getitem__"):
            items = [(str(c), data[c].to_numpy()) for c in data.columns]
        elif isinstance(data, dict):
            items = [(str(k), v) for k, v in data.items()]
        else:
            raise TypeError(
                f"the data are a CSV path, a pandas DataFrame or a dict of arrays, not "
                f"{type(data).__name__}"
            )
        for name, values in items:
            key = _DATA_ALIASES.get(name, name).lower()
            if key in _DATA_COLUMNS or key in _LABEL_COLUMNS:
                columns[key] = values
    for name in list(kwargs):
        key = _DATA_ALIASES.get(name, name)
        if key in _DATA_COLUMNS:
            columns[key] = kwargs.pop(name)
    if is_path:
        if columns:
            raise ValueError("give the data as a CSV path or as columns, not both")
        return None
    if not columns:
        raise ValueError(
            "no data: give a CSV path, a DataFrame or dict of columns, or the columns as "
            "keywords (z=..., amplitude=..., phase=...; or z_nm=..., amplitude_nm=..., "
            "phase_deg=...)"
        )
    return columns


def _csv_text(columns: Dict[str, Any]) -> str:
    """The columns as the CSV the command line reads, every number exact (repr)."""
    if not any(c in columns for c in _POSITIONS + ["setpoint_ratio"]):
        raise ValueError(
            "no position column: give z (m) or one of " + ", ".join(_POSITIONS)
            + " (or setpoint_ratio)"
        )
    arrays = {}
    for name, values in columns.items():
        a = _np.asarray(values)
        if a.ndim != 1:
            raise ValueError(f"column {name} is not one-dimensional (shape {a.shape})")
        if name in _LABEL_COLUMNS:
            text = [str(v) for v in a]
            if any("," in t or "\n" in t or '"' in t for t in text):
                raise ValueError(f"column {name} holds a label with a comma, quote or newline")
            arrays[name] = text
            continue
        try:
            a = a.astype(float)
        except (TypeError, ValueError):
            raise ValueError(f"column {name} is not numbers") from None
        bad = _np.flatnonzero(~_np.isfinite(a))
        if bad.size:
            raise ValueError(f"column {name} holds {a[bad[0]]} at index {bad[0]}: every value must be a finite number")
        arrays[name] = [repr(float(v)) for v in a]
    lengths = {name: len(v) for name, v in arrays.items()}
    if len(set(lengths.values())) > 1:
        raise ValueError(
            "the columns have different lengths: "
            + ", ".join(f"{k} {n}" for k, n in lengths.items())
        )
    names = list(arrays)
    rows = zip(*(arrays[n] for n in names))
    return ",".join(names) + "\n" + "".join(",".join(r) + "\n" for r in rows)


def _run_on_data(command: str, data: Any, setup: Optional[Setup], kwargs: Dict[str, Any]) -> Result:
    """Run ``command`` on a data file: ``data``'s path, or the columns given as arrays
    written to a CSV of its own (exact values) for the run."""
    import tempfile

    columns = _data_columns(data, kwargs)
    args = _argv(command, _options(setup, kwargs))
    if columns is None:
        return Result(command, _tapsim.run([args[0], _os.fspath(data)] + args[1:]))
    text = _csv_text(columns)
    with tempfile.TemporaryDirectory(prefix="tapsim-") as tmp:
        path = _os.path.join(tmp, "data.csv")
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)
        return Result(command, _tapsim.run([args[0], path] + args[1:]))


def fit(data: Any = None, setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """A measured approach curve fitted by the simulator (``tapsim fit``). The data: a
    CSV path (position, amplitude and/or phase columns with units in the header, as
    ``tapsim fit`` reads it), a pandas DataFrame or a dict whose columns are named so,
    or arrays as keywords -- ``z=``, ``amplitude=`` (m) and ``phase=`` (degrees), or
    by their CSV names (``z_nm=``, ``amplitude_ratio=``, ``phase_deg=``, ...): the
    same numbers, bit for bit, as the command line on that CSV. Returns ``parameters``
    (value, std_err, interval_68, interval_95, identifiable), ``identifiability``
    (singular_values, condition_number, correlations, notes), chi_square,
    ``converged``, ``diagnosis`` (describes_data, reasons, worst_points), the
    ``minima`` found, the fitted curve, ``left_out`` (the points left out because
    they graze a switch at the fitted parameters; ``keep_grazing=True`` keeps them;
    ``temperature="300K"`` fits them as the thermal averages an instrument reads);
    ``profile=True`` adds ``profiles``.
    ``law=["hybrid", "jkr"]`` fits each law: ``laws`` (one report per law) and
    ``comparison`` (ranking by AIC and BIC, ``verdict`` in words)."""
    return _run_on_data("fit", data, setup, kwargs)


def reconstruct(data: Any = None, setup: Optional[Setup] = None, /, **kwargs: Any) -> Result:
    """The force and the loss an AM curve implies (``tapsim reconstruct``). The data as
    :func:`fit` takes them (position, amplitude and phase), or with ``mode="fm"`` an FM
    curve (position, frequency_shift_hz, excitation_ratio, as :func:`fm` writes it):
    columns closest_m, force_n,
    e_ts_j, in_phase_force_n, frequency_shift (with ``with_law=True`` also
    law_approach_force_n and law_retract_force_n), and notes."""
    return _run_on_data("reconstruct", data, setup, kwargs)


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
