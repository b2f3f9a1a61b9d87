"""Fit an approach curve saved by an Asylum Research AFM (an Igor binary wave, .ibw).

Asylum's software saves a curve as one two-dimensional wave: a row per sample and a
column per channel, each column named by a dimension label (``ZSnsr``, ``Amp``,
``Phase``, ``Defl``, ...) and the run's settings in the wave's note (``key: value``
lines). This reads such a file with ``igor2`` (``pip install igor2``), keeps the columns
tapsim fits -- the Z sensor's height, the amplitude in metres (``Amp``; ``AmpV`` in
volts with the InvOLS the note or ``--invols`` gives) and the phase in degrees -- and
fits them with ``tapsim.fit``::

    python examples/ibw_fit.py CURVE.ibw --modulus 1GPa --work-of-adhesion 0.1J/m^2

Any further ``--flag value`` is passed to ``tapsim.fit`` (as ``tapsim fit --help``
lists them). tapsim's z grows away from the sample; ``--flip-z`` negates a Z sensor
that grows towards it (fit the ``z-offset`` if its zero is not the sample's).
"""

import sys
from typing import Any, Dict, List, Tuple

import numpy as np

#: Channel labels (lower case) and the keyword ``tapsim.fit`` takes each as.
CHANNELS = {
    "zsnsr": "z",
    "rawz": "z",
    "amp": "amplitude",
    "amplitude": "amplitude",
    "ampv": "amplitude_v",
    "phase": "phase",
}


def read_note(text: str) -> Dict[str, str]:
    """The wave note's ``key: value`` lines (Igor separates lines with CR)."""
    note = {}
    for line in text.replace("\r", "\n").split("\n"):
        key, sep, value = line.partition(":")
        if sep:
            note[key.strip()] = value.strip()
    return note


def read_curve(path: str) -> Tuple[Dict[str, np.ndarray], Dict[str, str]]:
    """The channels of the .ibw at ``path`` that ``tapsim.fit`` takes (by its keyword:
    z, amplitude or amplitude_v, phase), as float64 arrays, and the note."""
    from igor2 import binarywave

    wave = binarywave.load(path)["wave"]
    data = np.asarray(wave["wData"], dtype=float)
    if data.ndim != 2:
        raise ValueError(f"{path}: a curve is a two-dimensional wave, not {data.ndim}-D")
    labels: List[bytes] = wave["labels"][1] if len(wave["labels"]) > 1 else []
    # The first label names the dimension as a whole; then one a column.
    names = [label.decode("latin-1").strip("\x00") for label in labels[1:]]
    if len(names) != data.shape[1]:
        raise ValueError(f"{path}: the wave's {data.shape[1]} columns are not labelled")
    columns = {}
    for i, name in enumerate(names):
        key = CHANNELS.get(name.lower())
        if key is not None and key not in columns:
            columns[key] = data[:, i].copy()
    if "z" not in columns:
        raise ValueError(f"{path}: no Z sensor column (ZSnsr) among {names}")
    note = read_note(bytes(wave["note"]).decode("latin-1"))
    return columns, note


def fit_curve(path: str, flip_z: bool = False, **flags: Any) -> Any:
    """Read the curve at ``path`` and fit it: ``tapsim.fit`` on its arrays with
    ``flags``; an amplitude in volts is made metres with the note's ``InvOLS`` unless
    ``invols=`` is given."""
    import tapsim

    columns, note = read_curve(path)
    z = -columns["z"] if flip_z else columns["z"]
    data: Dict[str, Any] = {"z": z}
    if "phase" in columns:
        data["phase"] = columns["phase"]
    if "amplitude" in columns:
        data["amplitude"] = columns["amplitude"]
    elif "amplitude_v" in columns:
        data["amplitude_v"] = columns["amplitude_v"]
        if "invols" not in flags:
            if "InvOLS" not in note:
                raise ValueError(f"{path}: the amplitude is in volts and no InvOLS is given")
            flags["invols"] = float(note["InvOLS"])
    return tapsim.fit(**data, **flags)


def main(argv: List[str]) -> int:
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__)
        return 0 if argv else 2
    path, rest = argv[0], argv[1:]
    flags: Dict[str, Any] = {}
    flip_z = False
    i = 0
    while i < len(rest):
        flag = rest[i]
        if flag == "--flip-z":
            flip_z, i = True, i + 1
            continue
        if not flag.startswith("--") or i + 1 >= len(rest):
            print(f"expected --flag value, not {flag!r}", file=sys.stderr)
            return 2
        flags[flag[2:].replace("-", "_")] = rest[i + 1]
        i += 2
    result = fit_curve(path, flip_z=flip_z, **flags)
    for p in result.parameters:
        interval = p["interval_95"]
        said = f"95 %: {interval[0]:.6g} .. {interval[1]:.6g}" if interval else "no interval"
        print(f"{p['name']:>20} = {p['value']:.6g}  ({said})")
    print(f"{'chi^2/dof':>20} = {result.reduced_chi_square:.4g}")
    print(f"{'describes the data':>20} = {result.diagnosis['describes_data']}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
