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
    rc, text, _ = cli("fit", f"--log={out}", "--model=rigid3d",
                      "--format=json")
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
