"""The Python package against the command line it wraps, and against closed forms."""

import math
import os
import subprocess
import sys

import numpy as np
import pytest

import tapsim


def plain(value):
    """A result's value as the JSON it came from: arrays as lists, masked entries as
    None."""
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, np.ma.MaskedArray):
        return [plain(v) for v in value.tolist()]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, list):
        return [plain(v) for v in value]
    return value


# The defaults and five other setups, each as keyword arguments and as flags.
SETUPS = [
    {},
    {"law": "jkr", "separation": "14nm"},
    {"law": "hertz", "separation": "12nm", "viscosity": "50Pa·s"},
    {"setpoint": 0.8},
    {"law": "dmt", "hamaker": 1e-19, "stiffness": "2N/m", "resonance": "70kHz",
     "free_amplitude": "10nm", "separation": "8nm"},
    {"law": "hybrid", "separation": "20nm", "rupture_distance": "2nm"},
]


def flags(options):
    out = []
    for key, value in options.items():
        out.append(f"--{key.replace('_', '-')}={value if isinstance(value, str) else repr(value)}")
    return out


@pytest.mark.parametrize("options", SETUPS, ids=lambda o: ",".join(o) or "defaults")
def test_tap_is_the_command_line_bit_for_bit(cli, options):
    r = tapsim.tap(**options)
    expected = cli("tap", *flags(options))
    assert plain(r.to_dict()) == expected
    # The headline numbers, exactly (== on floats: the same bits).
    for key in ("amplitude_ratio", "phase_deg", "e_ts_j"):
        assert r[key] == expected[key]
        assert isinstance(r[key], float)


def test_columns_are_numpy_arrays_with_the_command_lines_values(cli):
    a = tapsim.approach(points=8)
    expected = cli("approach", "--points=8")
    assert isinstance(a.phase_deg, np.ndarray) and a.phase_deg.dtype == np.float64
    assert a.period.dtype == np.int64 or isinstance(a.period, np.ma.MaskedArray)
    assert len(a.separation_m) == 16  # approach and retract
    assert plain(a.to_dict()) == expected


def test_a_map_is_2d_with_its_axes_and_the_same_on_any_thread_count(cli):
    one, two = (tapsim.map(steps=4, threads=n) for n in (1, 2))
    assert plain(one.to_dict()) == plain(two.to_dict())
    m = tapsim.map(steps=4)
    assert m.grid["phase_deg"].shape == (4, 4)
    assert m.modulus_pa.shape == (4,) and m.work_of_adhesion_j_m2.shape == (4,)
    assert plain(m.to_dict()) == cli("map", "--steps=4") == plain(one.to_dict())


def test_bad_input_raises_value_error_with_the_command_lines_message(cli):
    with pytest.raises(ValueError) as e:
        tapsim.tap(stiffness="-1N/m")
    stderr = cli("tap", "--stiffness=-1N/m", expect_failure=True)
    assert stderr.strip() == f"error: {e.value}"
    with pytest.raises(ValueError, match="unexpected argument '--stifness'"):
        tapsim.tap(stifness=40)
    with pytest.raises(ValueError, match="setpoint lies between 0 and 1"):
        tapsim.contrast(setpoints=[1.5])
    with pytest.raises(TypeError):
        tapsim.tap(separation=object())


def test_setups_vary_and_run_in_parallel_as_one_by_one():
    base = tapsim.Setup(law="jkr", separation="14nm")
    varied = [base.replace(separation=f"{z}nm") for z in (12, 14, 16)]
    assert base.to_dict()["separation"] == "14nm"  # replace made new ones
    assert varied[1] == base
    many = tapsim.tap_many(varied)
    for setup, result in zip(varied, many):
        one = tapsim.tap(setup)
        assert plain(result.to_dict()) == plain(one.to_dict())
    assert tapsim.tap(base, separation="16nm").phase_deg == many[2].phase_deg


def test_a_model_is_tap_as_a_function_of_its_parameters():
    f = tapsim.model(["separation", "sample_modulus"], law="hertz")
    values = f(13e-9, 1e9)
    r = tapsim.tap(law="hertz", separation=13e-9, sample_modulus=1e9)
    assert values.tolist() == [r.amplitude_ratio, r.phase_deg]
    with pytest.raises(TypeError):
        f(13e-9)


def test_hysteresis_gives_the_papers_closed_forms():
    # JKR's pull-off under load control is 3π/2 (eq. 8); its loss per cycle Ŵ_JKR
    # (eq. 9) does not depend on μ, the hybrid's (18) is below it.
    h = tapsim.hysteresis(mu=5)
    assert h.pull_off_hat == pytest.approx(1.5 * math.pi, rel=1e-12)
    assert h.w_hat_hybrid < h.w_hat_jkr
    assert tapsim.hysteresis(mu=10).w_hat_jkr == h.w_hat_jkr


def test_peakforce_returns_the_channels_and_the_curve_as_arrays():
    # A Hertz contact: no loss, and the DMT fit of the retract returns the modulus given.
    r = tapsim.peakforce(law="hertz", separation="148.6nm", curve=True)
    assert r.regime == "period-1"
    ch = r.cycles[0]
    assert ch["dmt_modulus_pa"] == pytest.approx(r.modulus_given_pa, rel=5e-3)
    assert r.contact_loss_j == 0.0
    force, separation = r.curve["force_n"], r.curve["separation_m"]
    assert isinstance(force, np.ndarray) and force.shape == separation.shape
    assert force.max() == pytest.approx(ch["peak_force_n"], rel=1e-12)
    with pytest.raises(ValueError, match="not off-resonance"):
        tapsim.peakforce(modulation_frequency="300kHz")


def test_force_curve_returns_its_jumps_and_the_curve_as_arrays():
    # The hybrid law snaps in at a positive separation and pulls off at JKR's adhesion
    # (3/2)piR dgamma; the books close; the curve comes as arrays of at most `points`.
    r = tapsim.force_curve(curve=True, points=400)
    assert r.triggered and r.snap_in["separation_m"] > 0.5e-9
    radius, dgamma = 20e-9, 0.1
    assert r.channels["adhesion_n"] == pytest.approx(1.5 * math.pi * radius * dgamma, rel=1e-6)
    assert r.energy_balance_rel < 1e-6
    force, piezo = r.curve["force_n"], r.curve["piezo_m"]
    assert isinstance(force, np.ndarray) and force.shape == piezo.shape
    assert 400 <= len(force) <= 430
    assert force.max() == pytest.approx(r.channels["peak_force_n"], rel=1e-12)
    # A conservative law loses nothing in the contact; a keyword flag takes a `_`.
    hertz = tapsim.force_curve(law="hertz", from_="10nm")
    assert hertz.contact_loss_j == 0.0 and hertz.start_m == 10e-9
    with pytest.raises(ValueError, match="too fast for a force curve"):
        tapsim.force_curve(velocity="1m/s")


def test_fm_returns_the_frequency_shift_and_the_dissipation_channel_per_point():
    # JKR touches at every point from 19.5 nm: the excitation reads its loop per touch
    # (Anczykowski's formula) to 1e-3; one row a point in pandas.
    r = tapsim.fm(law="jkr", from_="19.5nm", to="17nm", points=4)
    assert r.law == "jkr" and r.amplitude_m == pytest.approx(20e-9)
    assert isinstance(r.frequency_shift_hz, np.ndarray) and len(r.frequency_shift_hz) == 4
    np.testing.assert_allclose(r.e_ts_from_excitation_j, r.loop_loss_j, rtol=1e-3)
    df = r.to_pandas()
    assert list(df["separation_m"]) == pytest.approx([19.5e-9, 18.666e-9, 17.833e-9, 17e-9], rel=1e-3)
    assert (df["excitation_ratio"] > 1.09).all()
    with pytest.raises(ValueError, match="relaxing sample"):
        tapsim.fm(law="hertz", unrelaxed_modulus="3GPa", relaxation_time="100ns")


def test_scan_in_peakforce_mode_returns_the_qnm_channels_per_pixel():
    r = tapsim.scan(mode="peakforce", pixels=4, no_retrace=True)
    assert r.adhesion_n.shape == (4,) and r.topography_m.shape == (4,)
    # The blend's two materials: the first half adheres more (0.1 against 0.08 J/m^2).
    assert r.adhesion_n[0] > r.adhesion_n[3]
    with pytest.raises(ValueError, match="add --mode peakforce"):
        tapsim.scan(peak_force="3nN")


def test_fm_under_the_thermal_force_adds_the_averaged_channels():
    r = tapsim.fm(setpoint="-200Hz", temperature="300K")
    # The average over the thermal motion lies within a few of its errors of the state.
    assert abs(r.thermal_frequency_shift_hz - r.frequency_shift_hz) < 5 * r.thermal_frequency_shift_std_err_hz
    assert r.thermal_e_ts_std_err_j > 0


def test_scan_in_fm_mode_returns_the_topography_shift_and_dissipation_as_an_image():
    lines, pixels = 2, 4
    r = tapsim.scan(mode="fm", lines=lines, pixels=pixels)
    img = r.to_xarray()
    for key in ("topography_m", "frequency_shift_hz", "dissipation_j", "excitation_ratio"):
        assert img[key].shape == (2, lines, pixels)
    trace = img["dissipation_j"].sel(direction="trace").values
    # The blend: A (the first half) loses seven times what B does, at -200 Hz held.
    assert (trace[:, 0] > 5 * trace[:, -1]).all()
    assert np.allclose(img["frequency_shift_hz"].sel(direction="trace").values[:, 0], -200.0)
    with pytest.raises(ValueError, match="add --mode fm"):
        tapsim.scan(frequency_shift="-100Hz")


def _read_gsf(path):
    """A Gwyddion Simple Field file, read as Gwyddion's user guide describes the format:
    the magic line, ``name = value`` lines, one to four NULs to a multiple of 4, then
    little-endian float32 values row by row."""
    raw = path.read_bytes()
    assert raw.startswith(b"Gwyddion Simple Field 1.0\n")
    end = raw.index(b"\0")
    header = dict(
        (k.strip(), v.strip())
        for k, v in (line.split("=", 1) for line in raw[:end].decode().splitlines()[1:])
    )
    start = (end // 4 + 1) * 4
    assert set(raw[end:start]) == {0}
    data = np.frombuffer(raw[start:], dtype="<f4")
    return header, data.reshape(int(header["YRes"]), int(header["XRes"]))


def test_an_image_file_where_none_may_be_written_is_an_exception(tmp_path):
    # sysfs refuses every writer, root too; nothing else of the run is written.
    if not os.path.isdir("/sys/kernel"):
        pytest.skip("no sysfs here")
    csv = tmp_path / "image.csv"
    with pytest.raises(ValueError, match="/sys/image.gwy"):
        tapsim.scan(lines=2, pixels=4, gwy="/sys/image.gwy", csv=str(csv))
    assert not csv.exists()


def test_a_scanned_image_opens_in_gwyddion(tmp_path):
    import shutil

    import gwyfile

    gwy, gsf = tmp_path / "image.gwy", tmp_path / "image.gsf"
    lines, pixels = 3, 5
    r = tapsim.scan(lines=lines, pixels=pixels, gwy=str(gwy), gsf=str(gsf))
    trace = r.direction == "trace"
    # The image as Gwyddion holds it: the top line (largest y) first.
    def grid(column):
        return column[trace].reshape(lines, pixels)[::-1]

    fields = gwyfile.util.get_datafields(gwyfile.load(str(gwy)))
    for title, column, unit in [
        ("Topography (trace)", r.topography_m, "m"),
        ("Phase (trace)", r.phase_deg, "deg"),
        ("Amplitude A/A0 (trace)", r.amplitude_ratio, ""),
    ]:
        f = fields[title]
        assert f.data.shape == (lines, pixels)
        assert (f.xreal, f.yreal) == (1e-6, 1e-6)
        assert f.si_unit_xy.unitstr == "m" and f.si_unit_z.unitstr == unit
        np.testing.assert_array_equal(f.data, grid(column))
    assert "Topography (retrace)" in fields and "Topography levelled (trace)" in fields
    header, data = _read_gsf(tmp_path / "image_topography_trace.gsf")
    assert (header["XRes"], header["YRes"], header["ZUnits"]) == ("5", "3", "m")
    np.testing.assert_array_equal(data, grid(r.topography_m).astype(np.float32))
    # Gwyddion itself renders both (CI installs it; elsewhere the check is skipped).
    thumbnailer = shutil.which("gwyddion-thumbnailer")
    if thumbnailer is None:
        if os.environ.get("TAPSIM_REQUIRE_GWYDDION"):
            pytest.fail("gwyddion-thumbnailer is not installed")
        pytest.skip("Gwyddion is not installed (apt-get install gwyddion)")
    for path in (gwy, tmp_path / "image_phase_trace.gsf"):
        png = tmp_path / (path.name + ".png")
        subprocess.run([thumbnailer, "gnome2", "64", str(path), str(png)], check=True)
        assert png.stat().st_size > 0


def test_results_go_to_pandas_and_xarray_with_every_column():
    pytest.importorskip("pandas")
    pytest.importorskip("xarray")
    # An approach curve: a row per point, every column the same numbers.
    a = tapsim.approach(points=6)
    df = a.to_pandas()
    assert len(df) == 12 and df.attrs["command"] == "approach"
    for key in ("separation_m", "amplitude_m", "phase_deg", "e_ts_j", "direction"):
        np.testing.assert_array_equal(df[key].to_numpy(), np.asarray(a[key]))
    # A map: a row per cell; as xarray a grid over (modulus_pa, work_of_adhesion_j_m2).
    m = tapsim.map(steps=3)
    ds = m.to_xarray()
    assert ds["phase_deg"].dims == ("modulus_pa", "work_of_adhesion_j_m2")
    np.testing.assert_array_equal(ds["modulus_pa"].values, m.modulus_pa)
    for key in ("phase_deg", "e_ts_j", "amplitude_ratio"):
        grid = np.ma.filled(np.ma.asarray(m.grid[key]).astype(float), np.nan)
        np.testing.assert_array_equal(ds[key].values, grid)
        np.testing.assert_array_equal(m.to_pandas()[key].to_numpy(), grid.reshape(-1))
    assert ds.attrs["law"] == "hybrid"
    # A scanned image: (direction, y_m, x_m), x ascending both ways.
    lines, pixels = 3, 4
    s = tapsim.scan(lines=lines, pixels=pixels)
    img = s.to_xarray()
    assert img["topography_m"].shape == (2, lines, pixels)
    trace = s.direction == "trace"
    np.testing.assert_array_equal(
        img["topography_m"].sel(direction="trace").values,
        s.topography_m[trace].reshape(lines, pixels),
    )
    back = s.topography_m[~trace].reshape(lines, pixels)[:, ::-1]
    np.testing.assert_array_equal(img["topography_m"].sel(direction="retrace").values, back)
    assert len(s.to_pandas()) == 2 * lines * pixels


def test_results_show_their_keys():
    r = tapsim.tap()
    assert "phase_deg" in dir(r) and "phase_deg" in r
    assert r.format_version == 2
    with pytest.raises(AttributeError, match="has no 'phase'"):
        r.phase
    assert "tap" in repr(r)


def test_ctrl_c_stops_a_long_map():
    # A 100 × 100 map takes 20 s on two cores; SIGINT a second in ends it at its next
    # cell with KeyboardInterrupt, and the process exits well before the map would.
    import signal
    import time

    # (The child turns Ctrl-C into KeyboardInterrupt itself: a job started in the
    # background by a non-interactive shell, as a CI runner may start it, inherits
    # SIGINT ignored, and Python then leaves it ignored.)
    script = (
        "import signal, sys, tapsim\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "print('started', flush=True)\n"
        "try:\n"
        "    tapsim.map(steps=100)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', flush=True)\n"
        "    sys.exit(3)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "started"
    time.sleep(1.0)
    p.send_signal(signal.SIGINT)
    sent = time.monotonic()
    out, _ = p.communicate(timeout=60)
    assert p.returncode == 3 and "interrupted" in out
    assert time.monotonic() - sent < 10


def test_a_bimodal_state_gives_each_modes_values_as_columns(cli):
    r = tapsim.tap(modes=2, drive2_amplitude="0.3nm")
    expected = cli("tap", "--modes=2", "--drive2-amplitude=0.3nm")
    assert r.common_period_periods == expected["common_period_periods"] == 4
    for key in ("amplitude_ratio", "phase_deg", "e_exchange_j", "energy_balance_rel"):
        column = r.modes[key]
        assert isinstance(column, np.ndarray) and column.dtype == np.float64
        assert column.tolist() == [m[key] for m in expected["modes"]]
    assert r.modes.mode.tolist() == [1, 2]
    # Energy goes round: what the tip force does on the modes is what the contact takes.
    assert abs(r.modes.e_exchange_j.sum() + r.e_ts_j) <= 1e-6 * r.modes.e_drive_j.sum()


def test_modes_without_a_common_period_give_averages_with_errors(cli):
    # The beam's f2 as it is (ratio tolerance 0): window averages, each with its error.
    r = tapsim.tap(modes=2, ratio_tolerance=0)
    expected = cli("tap", "--modes=2", "--ratio-tolerance=0")
    assert "no common period" in r.motion and r.converged
    for key in ("amplitude_ratio", "phase_deg", "phase_std_err_deg"):
        assert r.modes[key].tolist() == [m[key] for m in expected["modes"]]
    assert (r.modes.phase_std_err_deg < 1e-3).all()
    with pytest.raises(ValueError, match="no common denominator"):
        tapsim.tap(modes=2, ratio_tolerance=0, setpoint=0.8)


def test_fit_reads_the_curve_approach_writes_and_gives_it_back(cli, tmp_path):
    path = tmp_path / "curve.csv"
    tapsim.approach(**{"from": "18.5nm"}, to="8nm", points=8, no_retract=True, csv=str(path))
    r = tapsim.fit(path, modulus="0.8GPa", work_of_adhesion="0.12J/m^2")
    expected = cli("fit", str(path), "--modulus=0.8GPa", "--work-of-adhesion=0.12J/m^2")
    assert [p["value"] for p in r.parameters] == [p["value"] for p in expected["parameters"]]
    assert abs(r.parameters[1]["value"] / 0.1 - 1) < 1e-6
    with pytest.raises(ValueError, match="far to near"):
        rising = tmp_path / "rising.csv"
        rising.write_text("z_nm,phase_deg\n8,120\n9,121\n10,122\n")
        tapsim.fit(rising)


def test_fit_takes_arrays_and_gives_the_command_lines_numbers_bit_for_bit(cli, tmp_path):
    # The curve as arrays (keywords in SI, by CSV name, or a dict) fits exactly as the
    # same numbers in a CSV do on the command line.
    path = tmp_path / "curve.csv"
    tapsim.approach(**{"from": "18.5nm"}, to="8nm", points=8, no_retract=True, csv=str(path))
    table = np.genfromtxt(path, delimiter=",", names=True)
    z, amplitude, phase = table["separation_m"], table["amplitude_m"], table["phase_deg"]
    mine = tmp_path / "mine.csv"
    mine.write_text(
        "z_m,amplitude_m,phase_deg\n"
        + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in zip(z, amplitude, phase))
    )
    flags = dict(modulus="0.8GPa", work_of_adhesion="0.12J/m^2")
    expected = cli("fit", str(mine), "--modulus=0.8GPa", "--work-of-adhesion=0.12J/m^2")
    values = [p["value"] for p in expected["parameters"]]
    for r in [
        tapsim.fit(z=z, amplitude=amplitude, phase=phase, **flags),
        tapsim.fit(z_m=z, amplitude_m=amplitude, phase_deg=phase, **flags),
        tapsim.fit({"z_m": z, "amplitude_m": amplitude, "phase_deg": phase}, **flags),
    ]:
        assert [p["value"] for p in r.parameters] == values
        assert r.chi_square == expected["chi_square"]
    # Bad arrays: a clear exception each.
    for bad, says in [
        (dict(z=z, amplitude=amplitude[:-1], phase=phase), "different lengths"),
        (dict(z=z, phase=np.where(np.arange(len(z)) == 3, np.nan, phase)), "finite number"),
        (dict(amplitude=amplitude, phase=phase), "no position column"),
        (dict(z=z.reshape(2, -1), phase=phase), "one-dimensional"),
    ]:
        with pytest.raises(ValueError, match=says):
            tapsim.fit(**bad, **flags)
    with pytest.raises(ValueError, match="not both"):
        tapsim.fit(path, z=z)
    with pytest.raises(TypeError, match="a pandas DataFrame or a dict"):
        tapsim.fit([1, 2, 3])


def test_fit_ranks_several_laws(cli, tmp_path):
    # A DMT curve fitted with DMT and Hertz (a list is several --law flags): the data
    # prefer DMT, its attraction being in them; the same ranking as the command line's.
    path = tmp_path / "dmt.csv"
    law = dict(law="dmt", work_of_adhesion=0.02)
    tapsim.approach(**{"from": "24nm"}, to="12nm", points=12, no_retract=True, csv=str(path), **law)
    r = tapsim.fit(path, law=["dmt", "hertz"], work_of_adhesion=0.02, fit="modulus",
                   sigma_amplitude="0.02nm", sigma_phase=0.05)
    expected = cli("fit", str(path), "--law=dmt,hertz", "--work-of-adhesion=0.02",
                   "--fit=modulus", "--sigma-amplitude=0.02nm", "--sigma-phase=0.05")
    ranking = [row["law"] for row in r.comparison["ranking"]]
    assert ranking == [row["law"] for row in expected["comparison"]["ranking"]]
    assert ranking[0] == "dmt"
    assert "prefer dmt over hertz" in r.comparison["verdict"]
    assert r.laws["dmt"]["converged"]


def test_reconstruct_gives_the_force_of_the_curve_approach_writes(cli, tmp_path):
    path = tmp_path / "dmt.csv"
    law = dict(law="dmt", work_of_adhesion=0.02)
    tapsim.approach(**{"from": "30nm"}, to="6nm", points=120, no_retract=True, csv=str(path), **law)
    r = tapsim.reconstruct(path, with_law=True, **law)
    expected = cli("reconstruct", str(path), "--with-law", "--law=dmt", "--work-of-adhesion=0.02")
    assert r.force_n.tolist() == expected["force_n"]
    assert isinstance(r.closest_m, np.ndarray) and np.all(np.diff(r.closest_m) > 0)
    largest = np.max(np.abs(r.law_approach_force_n))
    assert np.max(np.abs(r.force_n - r.law_approach_force_n)) < 0.05 * largest
    with pytest.raises(ValueError, match="both the amplitude and the phase"):
        amplitude_only = tmp_path / "a.csv"
        amplitude_only.write_text("z_nm,amplitude_nm\n30,20\n29,19.9\n28,19.8\n")
        tapsim.reconstruct(amplitude_only)


def test_reconstruct_inverts_an_fm_curve_from_a_file_or_a_data_frame(cli, tmp_path):
    path = tmp_path / "fm.csv"
    args = dict(law="dmt", to="17nm", points=80)
    fm = tapsim.fm(**{"from": "30nm"}, csv=str(path), **args)
    r = tapsim.reconstruct(path, mode="fm", law="dmt", with_law=True)
    expected = cli("reconstruct", str(path), "--mode=fm", "--law=dmt", "--with-law")
    assert r.force_n.tolist() == expected["force_n"]
    # The columns of tapsim.fm as a DataFrame, exact rather than the CSV's ten digits.
    framed = tapsim.reconstruct(fm.to_pandas(), mode="fm", law="dmt")
    assert np.allclose(framed.force_n, r.force_n, rtol=0, atol=1e-6 * np.max(np.abs(r.force_n)))
    with pytest.raises(ValueError, match="excitation over its free value"):
        tapsim.reconstruct(dict(z_nm=[30, 25, 20], df_hz=[-1, -2, -5]), mode="fm")


def test_a_bimodal_scan_gives_each_pixels_higher_modes_as_2d_columns(cli):
    args = dict(modes=2, pixels=2, line_rate=400, no_retrace=True)
    r = tapsim.scan(**args)
    expected = cli("scan", "--modes=2", "--pixels=2", "--line-rate=400", "--no-retrace")
    assert r.modes.phase_deg.shape == (2, 1)
    assert r.modes.mode.tolist() == [[2], [2]]
    for key in ("amplitude_ratio", "phase_deg"):
        assert r.modes[key][:, 0].tolist() == [row[0][key] for row in expected["modes"]]
    assert r.phase_deg.tolist() == expected["phase_deg"]


def test_fit_leaves_out_a_point_grazing_at_the_fitted_parameters(tmp_path):
    # The branch-jumping curve as arrays (no grazing column, as an instrument writes
    # it): the point tapsim's approach flags as grazing the jump-in is the one the fit
    # leaves out at its own best parameters; keep_grazing=True fits it too.
    path = tmp_path / "curve.csv"
    tapsim.approach(**{"from": "24nm"}, to="8nm", points=40, no_retract=True,
                    modulus="0.8GPa", work_of_adhesion="0.07J/m^2", csv=str(path))
    table = np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding=None)
    flagged = [i for i, g in enumerate(table["grazing"]) if str(g).lower() == "true"]
    assert len(flagged) == 1
    arrays = dict(z=table["separation_m"], amplitude=table["amplitude_m"], phase=table["phase_deg"])
    flags = dict(fit="modulus,work-of-adhesion", modulus="0.6GPa", work_of_adhesion="0.1J/m^2")
    r = tapsim.fit(**arrays, **flags)
    assert r.left_out == flagged
    assert abs(r.parameters[1]["value"] / 0.07 - 1) < 1e-6
    kept = tapsim.fit(**arrays, **flags, keep_grazing=True, max_curves=3)
    assert kept.left_out == []
