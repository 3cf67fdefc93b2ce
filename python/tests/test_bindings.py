"""The Python module against the imusysid tool and the simulator's truth:
same JSON as `fit --format=json`, same files as `simulate`, arrays that
view the library's memory, errors as imusysid.Error, the GIL released."""

import json
import os
import threading
import time

import numpy as np
import pytest

import imusysid


def without_timing(value):
    """A fit's JSON without the keys that measure time (they differ from
    run to run)."""
    if isinstance(value, dict):
        return {k: without_timing(v) for k, v in value.items()
                if k not in ("wall_ms", "parameters")}
    if isinstance(value, list):
        return [without_timing(v) for v in value]
    return value


def read_csv(path):
    """The columns of a CSV with `#` comment lines, by header name."""
    lines = [line for line in open(path, encoding="utf-8")
             if not line.startswith("#")]
    names = lines[0].strip().split(",")
    values = np.loadtxt(lines[1:], delimiter=",", ndmin=2)
    return {name: values[:, i] for i, name in enumerate(names)}


def test_version_is_the_tools(cli):
    code, out, _ = cli("--version")
    assert code == 0
    assert out.strip() == "imusysid " + imusysid.__version__
    assert imusysid.__version__.count(".") == 2


def test_identify_gives_the_cli_json(cli, data_dir):
    log = str(data_dir / "paper_test2.csv")
    rc, out, _ = cli("fit", f"--log={log}", "--estimator=lm",
                     "--format=json", "--seed=3")
    assert rc == 0
    expected = json.loads(out)
    got = imusysid.identify(log, estimators="lm", seed=3)
    # Every key and value the tool prints, in its order: the same
    # library function builds both.
    assert without_timing(got) == without_timing(expected)
    assert list(got) == list(expected) + ["parameters"]
    # parameters gathers the physical parameters printed at the top level.
    assert got["parameters"] == {k: got[k] for k in
                                 ("r_m", "beta_deg", "alpha_deg", "mu")}


def test_identify_reads_bytes_and_names_the_source(data_dir):
    raw = (data_dir / "paper_test2.csv").read_bytes()
    from_bytes = imusysid.identify(raw, source="flight.csv", estimators="lm")
    from_file = imusysid.identify(data_dir / "paper_test2.csv",
                                  estimators="lm")
    assert from_bytes["log"] == "flight.csv"
    assert from_bytes["parameters"] == from_file["parameters"]


def test_identify_takes_a_log_as_arrays(data_dir):
    """A log read into arrays and fitted gives the file's own fit: the
    arrays go back to the library exactly."""
    path = data_dir / "paper_test2.csv"
    log = imusysid.read_log(path)
    from_arrays = imusysid.identify(log, estimators="lm")
    from_file = imusysid.identify(path, estimators="lm")
    assert from_arrays["log"] == str(path)
    assert from_arrays["parameters"] == from_file["parameters"]
    assert from_arrays["stderr"] == from_file["stderr"]
    del log["gz"]
    with pytest.raises(imusysid.Error, match="no 'gz' array"):
        imusysid.identify(log)


def test_read_log_views_the_library_memory(data_dir):
    path = data_dir / "paper_test1.csv"
    log = imusysid.read_log(path)
    columns = read_csv(path)
    np.testing.assert_array_equal(log["t"], columns["t"])
    np.testing.assert_array_equal(log["ax"], columns["ax"])
    np.testing.assert_array_equal(log["gy"], columns["gy"])
    # No copy: the arrays share one owner, the capsule holding the log.
    assert not log["ax"].flags.owndata
    assert log["ax"].base is log["gy"].base
    assert ("scenario", "paper_test1") in log["metadata"]
    assert log["parameters"] == []  # a CSV records no autopilot parameters


def test_simulate_writes_what_the_cli_writes(tmp_path, data_dir):
    out = tmp_path / "p1.csv"
    sim = imusysid.simulate("paper_test1", seed=1, out=out)
    # data/paper_test1.csv is `imusysid simulate --seed=1`, byte for byte.
    assert out.read_bytes() == (data_dir / "paper_test1.csv").read_bytes()
    truth = (data_dir / "paper_test1.truth.json").read_text()
    assert sim["truth"] == json.loads(truth)
    assert sim["files"] == [str(tmp_path / "p1.truth.json"), str(out)]
    log = imusysid.read_log(out)
    np.testing.assert_allclose(sim["log"]["ax"], log["ax"], rtol=1e-8)


def test_simulate_3d_and_identify_rigid3d(tmp_path, cli):
    out = str(tmp_path / "h.ulg")
    sim = imusysid.simulate("pitch_laps_3d", seed=2, out=out, format="ulog")
    assert sim["three_d"]
    assert len(sim["logs"]) == len(sim["truth"]["imus"]) == 3
    # The tool plans the withheld y (--plan_withheld, on there); the
    # binding, which fleets call per flight, does not.
    rc, text, _ = cli("fit", f"--log={out}", "--model=rigid3d",
                      "--plan_withheld=false", "--format=json")
    assert rc == 0
    got = imusysid.identify(out, model="rigid3d")
    assert without_timing(got) == without_timing(json.loads(text))
    # The ULog carries instance 0 at full rate (sensor_combined), the
    # others at 1 Hz (PX4's default profile): they are skipped, with why.
    assert [imu.get("fitted", True) for imu in got] == [True, False, False]
    assert "logged at 1 Hz" in got[1]["reason"]
    # x and z (pitch laps determine them) near the truth: 1 cm is over ten
    # times the fit's standard errors on this flight.
    fitted = got[0]["imu_position_frd_m"]
    for axis in (0, 2):
        assert fitted[axis] == pytest.approx(
            sim["truth"]["imus"][0]["p_frd_m"][axis], abs=0.01)


def test_fit_arrays_matches_the_cli_problem_fit(tmp_path, cli, data_dir):
    problem = tmp_path / "P.csv"
    rc, _, _ = cli("export-problem", f"--log={data_dir / 'model_exact.csv'}",
                   f"--out={problem}")
    assert rc == 0
    rc, text, _ = cli("fit", f"--problem={problem}", "--model=paper",
                      "--estimator=all", "--format=json")
    assert rc == 0
    expected = json.loads(text)
    gravity = 9.80665
    for line in problem.read_text().splitlines():
        if line.startswith("# gravity:"):
            gravity = float(line.split(":")[1])
    p = read_csv(problem)
    got = imusysid.fit(p["t"], p["f"], p["omega"], p["omega_dot"], v=p["v"],
                       theta=p["theta"], f_z=p["f_z"], model="paper",
                       estimators="all", source=expected[0]["log"],
                       gravity=gravity)
    assert len(got) == len(expected) >= 2
    added = ("estimate", "covariance", "parameter_names")
    for g, e in zip(got, expected):
        # The arrays carry no plane or velocity source ("unknown"); a
        # problem file names them in its header.
        mine = {k: v for k, v in g.items()
                if k not in added + ("plane", "velocity")}
        theirs = {k: v for k, v in e.items() if k not in ("plane",
                                                          "velocity")}
        assert without_timing(mine) == without_timing(theirs)
        assert g["parameter_names"][:4] == ["r", "beta", "alpha", "mu"]
        if e["stderr"]["r_m"] is None:
            continue
        # The covariance is the one the standard errors come from.
        se = np.sqrt(np.diag(g["covariance"]))
        assert se[0] == pytest.approx(e["stderr"]["r_m"], rel=1e-12)
        assert g["estimate"][0] == pytest.approx(e["raw_parameters"]["r_m"],
                                                 rel=1e-15)


def test_errors_are_imusysid_error_with_the_library_message(tmp_path,
                                                            data_dir):
    missing = str(tmp_path / "missing.csv")
    with pytest.raises(imusysid.Error) as e:
        imusysid.identify(missing)
    assert missing in str(e.value) and e.value.code == "NOT_FOUND"
    assert isinstance(e.value, ValueError)
    bad = tmp_path / "bad.csv"
    bad.write_text("t,ax,ay,az,gx,gy,gz\n0,1,2,3,4,5,abc\n")
    with pytest.raises(imusysid.Error, match="bad.csv:2"):
        imusysid.read_log(bad)
    with pytest.raises(imusysid.Error, match="nosuchmodel"):
        imusysid.identify(data_dir / "paper_test2.csv", model="nosuchmodel")
    with pytest.raises(TypeError, match="unknown option"):
        imusysid.identify(data_dir / "paper_test2.csv", colour="red")


def test_identify_releases_the_gil(data_dir):
    """Two fits in two threads overlap in time: with the GIL held the
    second could only start after the first returned. On an idle machine
    with two CPUs they also take less than 1.6 times one fit's time."""
    log = str(data_dir / "paper_test1.csv")
    spans = []

    def one():
        start = time.perf_counter()
        imusysid.identify(log, model="consistent",
                          estimators=["ga+lm", "hybrid"])
        spans.append((start, time.perf_counter()))

    one()
    single = spans[0][1] - spans[0][0]
    assert single >= 0.3, "the fit is too short to show parallel work"
    spans.clear()
    threads = [threading.Thread(target=one) for _ in range(2)]
    start = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    both = time.perf_counter() - start
    (a0, a1), (b0, b1) = sorted(spans)
    # The later start came before the earlier end by most of a fit.
    assert min(a1, b1) - b0 > 0.5 * single
    free_cpus = (os.cpu_count() or 1) - os.getloadavg()[0]
    if free_cpus < 1.8:
        pytest.skip(f"{free_cpus:.1f} CPUs free: overlap shown, speed-up "
                    "not measurable")
    assert both < 1.6 * single


# --- A log as arrays round trips for every reader and every scenario.

def position(result):
    """The fitted position of a 3-D fit (its first IMU) and its standard
    errors."""
    first = result[0] if isinstance(result, list) else result
    return first["fitted_position_frd_m"], first["imu_position_frd_stderr_m"]


@pytest.fixture(scope="module")
def logs_3d(tmp_path_factory):
    """One 3-D flight written as the tool writes it: CSV (one file per
    IMU), ULog and DataFlash."""
    folder = tmp_path_factory.mktemp("logs3d")
    paths = {}
    for kind, name in (("csv", "f.csv"), ("ulog", "f.ulg"),
                       ("dataflash", "f.bin")):
        sim = imusysid.simulate("pitch_laps_3d", seed=3, format=kind,
                                out=folder / name)
        paths[kind] = sim["files"][1]
    return paths


@pytest.mark.parametrize("kind", ["csv", "ulog", "dataflash"])
def test_3d_log_as_arrays_fits_as_the_file(logs_3d, kind):
    """read_log's arrays of a 3-D log (a CSV with empty estimator cells, a
    ULog, a DataFlash log) fit as the file's instance 0 does, exactly: the
    arrays go back as text that reads to the same numbers."""
    path = logs_3d[kind]
    from_arrays = imusysid.identify(imusysid.read_log(path), model="rigid3d")
    from_file = imusysid.identify(path, model="rigid3d", imu=0)
    got, se = position(from_arrays)
    assert len(got) == 3 and all(isinstance(v, float) for v in got + se)
    assert (got, se) == position(from_file)
    # Every other key too, but the source's name.
    first = (from_file[0] if isinstance(from_file, list) else from_file)
    assert first["log"] == path
    mine = {k: v for k, v in from_arrays.items() if k != "log"}
    theirs = {k: v for k, v in first.items() if k != "log"}
    assert without_timing(mine) == without_timing(theirs)


@pytest.mark.parametrize("scenario,model", [("paper_test2", None),
                                            ("pitch_laps_3d", "rigid3d")])
def test_simulate_result_fits_as_its_file(scenario, model):
    """identify(simulate(...)): the flight's arrays (the first IMU of a 3-D
    flight) fit as the file simulate writes of them, which holds 9
    significant digits: the same fit to within that rounding."""
    sim = imusysid.simulate(scenario, seed=2, return_bytes=True)
    from_arrays = imusysid.identify(sim, model=model, estimators="lm"
                                    if model is None else None)
    from_file = imusysid.identify(sim["bytes"][0], model=model,
                                  estimators="lm" if model is None else None)
    if sim["three_d"]:
        got, want = position(from_arrays)[0], position(from_file)[0]
        truth = sim["truth"]["imus"][0]["p_frd_m"]
        for axis in (0, 2):  # pitch laps determine x and z
            assert got[axis] == pytest.approx(want[axis], abs=1e-5)
            assert got[axis] == pytest.approx(truth[axis], abs=0.01)
    else:
        assert from_arrays["r_m"] == pytest.approx(from_file["r_m"],
                                                   rel=1e-6)
        assert from_arrays["r_m"] == pytest.approx(sim["truth"]["r_m"],
                                                   abs=0.02)
    # A 3-D flight's other IMUs by imu=; every IMU at once is the binary
    # log's (a log as arrays holds one).
    if sim["three_d"]:
        second = imusysid.identify(sim, model="rigid3d", imu=1)
        assert position(second)[0] != position(from_arrays)[0]
        with pytest.raises(imusysid.Error, match="holds one IMU"):
            imusysid.identify(sim, model="rigid3d", imu=-1)


def test_log_arrays_are_checked_where_they_are(data_dir):
    """Bad samples are named by array and sample, not by a line of the CSV
    text written from them."""
    log = imusysid.read_log(data_dir / "paper_test2.csv")
    log = {k: (np.array(v) if k in ("t", "ax") else v)
           for k, v in log.items()}
    log["ax"][5] = np.nan
    with pytest.raises(imusysid.Error, match="array 'ax' sample 5 is nan"):
        imusysid.identify(log)
    log["ax"][5] = 0.0
    log["t"][7] = log["t"][6]
    with pytest.raises(imusysid.Error, match="array 't' sample 7"):
        imusysid.identify(log)
    with pytest.raises(imusysid.Error, match="no 't' array"):
        imusysid.identify({"logs_of": []})


# --- Arguments are checked as the tool checks its flags.

def test_fit_refuses_gravity_and_arrays_the_tool_would(tmp_path, data_dir):
    p = read_csv(data_dir / "paper_test2.csv")
    n = 200
    args = (p["t"][:n], p["ax"][:n], p["gy"][:n], np.zeros(n))
    for g, fragment in ((np.nan, "must be a finite number"),
                        (0.0, "outside [0.1, 100]"),
                        (-9.8, "outside [0.1, 100]"),
                        (9806.65, "outside [0.1, 100]")):
        with pytest.raises(imusysid.Error, match=re_escape(fragment)) as e:
            imusysid.fit(*args, v=np.zeros(n), gravity=g)
        assert e.value.code == "INVALID_ARGUMENT"
    with pytest.raises(TypeError, match="a real number is required"):
        imusysid.fit(*args, v=np.zeros(n), gravity="9.8")
    # A complex array would lose its imaginary part in a conversion.
    with pytest.raises(TypeError, match="f_x: an array of real numbers"):
        imusysid.fit(args[0], args[1] + 1j, *args[2:], v=np.zeros(n))
    with pytest.raises(TypeError, match="v: an array of real numbers"):
        imusysid.fit(*args, v=["1"] * n)
    bad = args[1].copy()
    bad[3] = np.inf
    with pytest.raises(imusysid.Error, match="not finite"):
        imusysid.fit(args[0], bad, *args[2:], v=np.zeros(n))


def test_options_are_checked_as_the_flags(data_dir):
    log = data_dir / "paper_test2.csv"
    with pytest.raises(imusysid.Error, match="t_start=nan: the value must "
                                             "be a finite number"):
        imusysid.identify(log, t_start=float("nan"))
    with pytest.raises(ValueError, match="finite"):
        imusysid.identify(log, cutoff_hz=float("inf"))
    with pytest.raises(imusysid.Error, match=re_escape("max_time_s=-1; "
                                                       "required >= 0")):
        imusysid.identify(log, max_time_s=-1)
    for name, value in (("t_start", "10"), ("imu", "1"), ("seed", 1.5),
                        ("threads", True), ("trace", "yes"),
                        ("cutoff_hz", 2 + 0j)):
        with pytest.raises(TypeError, match=f"{name}="):
            imusysid.identify(log, **{name: value})
    with pytest.raises(TypeError, match="an integer is required"):
        imusysid.read_log(log, imu="0")
    with pytest.raises(TypeError, match="give a number as a number"):
        imusysid.simulate("paper_test2", r_m="0.2")
    with pytest.raises(imusysid.Error, match="seed=-1; required in"):
        imusysid.simulate("paper_test2", seed=-1)
    # Long text from an argument is cut in the message.
    with pytest.raises(TypeError) as e:
        imusysid.identify(log, seed="x" * 500)
    assert "x" * 40 + "..." in str(e.value) and "x" * 41 not in str(e.value)


def test_imu_minus_one_means_every_instance(logs_3d, data_dir):
    """imu=-1 is every instance wherever it appears: identify with a 3-D
    model fits them all; where one instance is needed it is refused with
    why, never taken as another instance."""
    every = imusysid.identify(logs_3d["ulog"], model="rigid3d", imu=-1)
    default = imusysid.identify(logs_3d["ulog"], model="rigid3d")
    assert len(every) == len(default) == 3
    assert position(every) == position(default)
    with pytest.raises(imusysid.Error, match="every instance"):
        imusysid.read_log(logs_3d["ulog"], imu=-1)
    with pytest.raises(imusysid.Error, match="applies to the 3-D models"):
        imusysid.identify(data_dir / "paper_test2.csv", imu=-1)
    with pytest.raises(imusysid.Error, match="imu=-2; required 0, 1 or 2"):
        imusysid.identify(data_dir / "paper_test2.csv", imu=-2)
    with pytest.raises(imusysid.Error, match="imu=3; required"):
        imusysid.read_log(logs_3d["ulog"], imu=3)


def test_unknown_scenario_lists_every_scenario():
    with pytest.raises(imusysid.Error) as e:
        imusysid.simulate("bogus")
    assert e.value.code == "NOT_FOUND"
    for name in imusysid.scenario_names():
        assert name in str(e.value)
    assert "figure8_3d" in str(e.value) and "paper_test1" in str(e.value)
    with pytest.raises(imusysid.Error, match=re_escape("'" + "y" * 40 +
                                                       "...'")):
        imusysid.simulate("y" * 300)


def re_escape(text):
    import re
    return re.escape(text)
