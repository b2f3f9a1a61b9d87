"""A measured file read: an Asylum Research approach curve saved as an Igor binary wave
(.ibw), read with igor2 and fitted with tapsim.fit by examples/ibw_fit.py. The test
writes the .ibw itself, from the format's description (WaveMetrics' Technical Note
PN003, version 5: a 64-byte binary header, a 320-byte wave header, the data in column
order, then the note and the dimension labels, 32 bytes each), since igor2 only reads."""

import importlib.util
import pathlib
import struct
import subprocess
import sys

import numpy as np
import pytest

import tapsim

EXAMPLE = pathlib.Path(__file__).resolve().parents[2] / "examples" / "ibw_fit.py"


def example():
    spec = importlib.util.spec_from_file_location("ibw_fit", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_ibw(path, columns, note=""):
    """A two-dimensional double-precision wave, a row per sample and a column per entry
    of ``columns`` (label -> array), its columns labelled, ``note`` its wave note."""
    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], dtype="<f8") for n in names])
    rows, cols = data.shape
    body = data.tobytes(order="F")
    note_bytes = note.encode("latin-1")
    # Dimension 1's labels: the dimension's own (empty), then a column's each.
    labels = b"".join(name.encode("latin-1").ljust(32, b"\0") for name in ["", *names])
    fields = [  # WaveHeader5, in order (2-byte packing)
        ("i", 0), ("I", 0), ("I", 0),  # next, creationDate, modDate
        ("i", rows * cols), ("h", 4), ("h", 0),  # npnts, type (NT_FP64), dLock
        ("6s", b""), ("h", 1), ("32s", b"curve"),  # whpad1, whVersion, bname
        ("i", 0), ("i", 0),  # whpad2, dFolder
        ("4i", (rows, cols, 0, 0)),  # nDim
        ("4d", (1.0,) * 4), ("4d", (0.0,) * 4),  # sfA, sfB
        ("4s", b""), ("16s", b""),  # dataUnits, dimUnits
        ("h", 0), ("h", 0), ("d", 0.0), ("d", 0.0),  # fsValid, whpad3, full scales
        ("i", 0), ("4i", (0,) * 4), ("4i", (0,) * 4), ("i", 0),  # handles
        ("64s", b""),  # whUnused
        ("h", 0), ("h", 0), ("h", 0), ("b", 0), ("b", 0),  # modified flags, bits
        ("i", 0), ("i", 0), ("h", 0), ("h", 0), ("i", 0), ("i", 0),  # formula .. sIndices
    ]
    wave_header = b"".join(
        struct.pack("<" + f, *(v if isinstance(v, tuple) else (v,))) for f, v in fields
    )
    assert len(wave_header) == 320

    def binary_header(checksum):
        return struct.pack(
            "<hhiiii4i4iiii",
            5, checksum, 320 + len(body), 0, len(note_bytes), 0,
            0, 0, 0, 0,
            0, len(labels), 0, 0,
            0, 0, 0,
        )

    # The checksum makes the 16-bit words of both headers sum to 0.
    words = struct.unpack("<192h", binary_header(0) + wave_header)
    checksum = -sum(words) & 0xFFFF
    checksum = checksum - 0x10000 if checksum >= 0x8000 else checksum
    header = binary_header(checksum)
    assert sum(struct.unpack("<192h", header + wave_header)) & 0xFFFF == 0
    pathlib.Path(path).write_bytes(header + wave_header + body + note_bytes + labels)


@pytest.fixture(scope="module")
def curve(tmp_path_factory):
    """An approach curve tapsim wrote (the hybrid law, 8 points from 18.5 to 8 nm), its
    columns, and the same as an Asylum .ibw."""
    tmp = tmp_path_factory.mktemp("ibw")
    csv = tmp / "curve.csv"
    tapsim.approach(**{"from": "18.5nm"}, to="8nm", points=8, no_retract=True, csv=str(csv))
    table = np.genfromtxt(csv, delimiter=",", names=True)
    z, amplitude, phase = table["separation_m"], table["amplitude_m"], table["phase_deg"]
    ibw = tmp / "curve.ibw"
    note = "SpringConstant: 40\rInvOLS: 5e-08\rScanRate: 1\r"
    write_ibw(ibw, {"Defl": np.zeros_like(z), "ZSnsr": z, "Amp": amplitude, "Phase": phase}, note)
    mine = tmp / "mine.csv"
    mine.write_text(
        "z_m,amplitude_m,phase_deg\n"
        + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in zip(z, amplitude, phase))
    )
    return dict(ibw=ibw, csv=mine, z=z, amplitude=amplitude, phase=phase, tmp=tmp)


def test_igor2_reads_the_written_wave_as_asylum_lays_it_out(curve):
    columns, note = example().read_curve(str(curve["ibw"]))
    assert set(columns) == {"z", "amplitude", "phase"}
    for key in ["z", "amplitude", "phase"]:
        assert np.array_equal(columns[key], curve[key]), key
    assert note["SpringConstant"] == "40" and float(note["InvOLS"]) == 5e-8


def test_the_ibw_example_fits_as_the_command_line_does(cli, curve):
    flags = dict(modulus="0.8GPa", work_of_adhesion="0.12J/m^2")
    expected = cli("fit", str(curve["csv"]), "--modulus=0.8GPa", "--work-of-adhesion=0.12J/m^2")
    r = example().fit_curve(str(curve["ibw"]), **flags)
    assert [p["value"] for p in r.parameters] == [p["value"] for p in expected["parameters"]]
    assert r.chi_square == expected["chi_square"]
    # The script itself, as the docs run it.
    out = subprocess.run(
        [sys.executable, str(EXAMPLE), str(curve["ibw"]), "--modulus", "0.8GPa",
         "--work-of-adhesion", "0.12J/m^2"],
        capture_output=True, text=True,
    )
    assert out.returncode == 0, out.stderr
    first = expected["parameters"][0]
    assert f"{first['name']:>20} = {first['value']:.6g}" in out.stdout


def test_an_amplitude_in_volts_takes_the_notes_invols(cli, curve):
    tmp = curve["tmp"]
    volts = tmp / "volts.ibw"
    write_ibw(volts, {"ZSnsr": curve["z"], "AmpV": curve["amplitude"] / 5e-8,
                      "Phase": curve["phase"]}, "InvOLS: 5e-08\r")
    flags = dict(modulus="0.8GPa", work_of_adhesion="0.12J/m^2")
    r = example().fit_curve(str(volts), **flags)
    expected = example().fit_curve(str(curve["ibw"]), **flags)
    for a, b in zip(r.parameters, expected.parameters):
        assert a["value"] == pytest.approx(b["value"], rel=1e-9)
    bare = tmp / "bare.ibw"
    write_ibw(bare, {"ZSnsr": curve["z"], "AmpV": curve["amplitude"] / 5e-8})
    with pytest.raises(ValueError, match="no InvOLS"):
        example().fit_curve(str(bare), **flags)
    nameless = tmp / "nameless.ibw"
    write_ibw(nameless, {"Height": curve["z"], "Amp": curve["amplitude"]})
    with pytest.raises(ValueError, match="no Z sensor column"):
        example().read_curve(str(nameless))
