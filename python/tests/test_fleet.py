"""imusysid.fleet on a local Dask cluster of two worker processes: one row
per log, a bad log kept as an error row, a second run resuming from the
output; and one Monte Carlo seed against the simulator's truth."""

import json
import os
import shutil
import time

import pandas as pd
import pytest

import imusysid
from imusysid import fleet


@pytest.fixture(scope="module")
def scheduler():
    """A local cluster of two worker processes, shared by the tests that
    pass its address as --scheduler (starting one takes seconds)."""
    from distributed import LocalCluster
    cluster = LocalCluster(n_workers=2, threads_per_worker=1,
                           processes=True, dashboard_address=None)
    yield cluster.scheduler_address
    cluster.close()


@pytest.fixture
def logs(tmp_path, data_dir):
    paths = []
    for name in ("paper_test2.csv", "model_exact.csv"):
        shutil.copy(data_dir / name, tmp_path / name)
        paths.append(str(tmp_path / name))
    bad = tmp_path / "bad.csv"
    bad.write_text("t,ax,ay,az,gx,gy,gz\n0,0,0,9.8,0,0,0\n1,0,0,x,0,0,0\n")
    paths.append(str(bad))
    return paths


def test_fit_on_two_worker_processes_then_resume(tmp_path, logs, capsys,
                                                 scheduler):
    out = str(tmp_path / "results.csv")
    argv = ["fit", *logs, f"--out={out}", f"--scheduler={scheduler}",
            "--estimator=lm", "--no-progress"]
    assert fleet.main(argv) == fleet.EXIT_OK
    rows = pd.read_csv(out, float_precision="round_trip").set_index("log")
    assert sorted(rows.index) == sorted(logs)
    # Worker processes did the work, not this one.
    pids = {w.split(":")[1] for w in rows["worker"]}
    assert str(os.getpid()) not in pids
    good = rows.loc[logs[0]]
    expected = imusysid.identify(logs[0], estimators="lm")
    assert good["status"] == "ok"
    assert good["r_m"] == expected["r_m"]
    assert good["stderr.r_m"] == expected["stderr"]["r_m"]
    bad = rows.loc[logs[2]]
    assert bad["status"] == "error"
    assert bad["error_code"] == "INVALID_ARGUMENT"
    assert "bad.csv:3" in bad["error"]
    with open(fleet.jsonl_path(out), encoding="utf-8") as f:
        records = [json.loads(line) for line in f]
    assert len(records) == 3
    assert {r["key"] for r in records} == set(rows["key"])

    # The same command again runs nothing (every key is in the output)
    # and needs no cluster; --strict reports the bad log's refusal.
    capsys.readouterr()
    # Nothing listens there: a run that tried to connect would fail.
    argv[argv.index(f"--scheduler={scheduler}")] = \
        "--scheduler=tcp://127.0.0.1:1"
    assert fleet.main(argv + ["--strict"]) == fleet.EXIT_BAD_INPUT
    assert "3 of 3 tasks already in" in capsys.readouterr().err
    again = pd.read_csv(out)
    assert len(again) == 3
    # Other options are other work: a new key for every log.
    keys = {fleet.task_key(b"x", {"seed": 1}), fleet.task_key(b"x",
                                                              {"seed": 2})}
    assert len(keys) == 2


def test_bad_command_line_is_exit_2(tmp_path, capsys):
    missing = str(tmp_path / "missing.csv")
    assert fleet.main(["fit", missing, f"--out={tmp_path / 'r.csv'}"]) == 2
    assert missing in capsys.readouterr().err
    with pytest.raises(SystemExit) as e:
        fleet.main(["bench", "--seeds=x", "--out=d"])
    assert e.value.code == 2
    assert fleet.main(["bench", "--preset=nope",
                       f"--out={tmp_path / 'd'}"]) == 2
    log = str(tmp_path / "log.csv")
    open(log, "w").close()
    assert fleet.main(["fit", log, f"--out={log}"]) == 2
    assert "both a log and the output" in capsys.readouterr().err
    unwritable = str(tmp_path / "no" / "such" / "r.csv")
    assert fleet.main(["fit", log, f"--out={unwritable}"]) == 2
    assert "r.csv': No such file or directory" in capsys.readouterr().err


def test_one_bench_seed_is_near_the_truth():
    record = fleet.bench_task("paper_test2", 5, {"model": "consistent"})
    assert record["status"] == "ok", record["error"]
    row = fleet._row(record)
    assert row["truth.r_m"] == 0.213  # data/paper_test2.truth.json
    # One seed's error against the truth: the Monte Carlo spread of r on
    # paper_test2 is a few millimetres (docs/benchmarks.md); 2 cm is far
    # outside it, so a wrong truth or a wrong seed fails.
    assert abs(row["error.r_m"]) < 0.02
    assert abs(row["error.beta_deg"]) < 5.0
    summary = fleet.summarize_bench(pd.DataFrame([row, row]))
    assert summary.loc[0, "seeds"] == 2
    assert summary.loc[0, "bias.r_m"] == pytest.approx(row["error.r_m"])


def test_bench_command_writes_rows_summary_and_timing(tmp_path, scheduler,
                                                      data_dir):
    out = tmp_path / "mc"
    argv = ["bench", "--scenarios=paper_test2", "--seeds=2", f"--out={out}",
            f"--scheduler={scheduler}", "--no-progress"]
    assert fleet.main(argv) == fleet.EXIT_OK
    rows = pd.read_csv(out / "monte_carlo.csv", float_precision="round_trip")
    assert sorted(rows["seed"]) == [1, 2]
    assert (rows["status"] == "ok").all()
    # data/paper_test2.csv is this scenario's seed 2: the same fit.
    bundled = imusysid.identify(data_dir / "paper_test2.csv",
                                model="consistent", seed=2)
    assert rows.set_index("seed").loc[2, "r_m"] == bundled["r_m"]
    assert rows.set_index("seed").loc[1, "r_m"] != bundled["r_m"]
    summary = pd.read_csv(out / "summary.csv")
    assert summary.loc[0, "seeds"] == 2
    assert abs(summary.loc[0, "bias.r_m"]) < 0.02
    timing = json.loads((out / "timing.json").read_text())
    assert timing["tasks"] == 2 and timing["workers"] == 2


def test_inputs_and_outputs_are_refused_as_the_tool_refuses_them(
        tmp_path, capsys):
    """Every input and output is checked before any work starts (no
    cluster is started here: a run that got that far would fail on the
    scheduler address), each refusal one line and exit 2."""
    nowhere = "--scheduler=tcp://127.0.0.1:1"
    log = tmp_path / "log.csv"
    log.write_text("t,ax,ay,az,gx,gy,gz\n")
    out = f"--out={tmp_path / 'r.csv'}"

    def refused(argv, fragment):
        capsys.readouterr()
        start = time.perf_counter()
        assert fleet.main(argv + [nowhere, "--no-progress"]) == 2
        assert time.perf_counter() - start < 5
        err = capsys.readouterr().err
        assert fragment in err, err
        assert err.count("\n") == 1 and "Traceback" not in err
        return err

    # A device would be read until memory runs out; a log over the
    # library's 1 GiB limit is refused before it is read (a sparse file).
    refused(["fit", "/dev/zero", out], "cannot read '/dev/zero': it is a "
                                       "character device, not a regular file")
    big = tmp_path / "big.csv"
    with open(big, "wb") as f:
        f.truncate((1 << 30) + 1)
    refused(["fit", str(big), out], "inputs may hold at most 1073741824")
    # An output the run could not write: a device (read as earlier results
    # or replaced otherwise), a folder.
    refused(["fit", str(log), "--out=/dev/full"],
            "cannot write '/dev/full': it is a character device, not a "
            "regular file")
    refused(["fit", str(log), f"--out={tmp_path}"], "it is a folder")
    assert not os.path.exists("/dev/full.jsonl")
    # bench's --out is a folder: an existing file is refused in one line.
    bench = ["bench", "--scenarios=paper_test2", "--seeds=1"]
    refused(bench + [f"--out={log}"], "is a regular file, not a folder")
    (tmp_path / "mc").mkdir()
    os.symlink("/dev/full", tmp_path / "mc" / "summary.csv")
    refused(bench + [f"--out={tmp_path / 'mc'}"],
            "summary.csv': it is a character device")
    # Long fields quoted from the command line are cut.
    err = refused(["bench", "--scenarios=" + "z" * 300,
                   f"--out={tmp_path / 'd'}"],
                  "z" * 40 + "...")
    assert "z" * 41 not in err
    with pytest.raises(SystemExit) as e:
        fleet.main(["fit", str(log), out, "--imu=5"])
    assert e.value.code == 2


def test_3d_bench_rows_carry_the_error_per_axis_as_the_tool_does(cli,
                                                                 tmp_path):
    """A rigid3d seed's row: position, σ̂ and error per axis in the IMU's
    axes, the same numbers `imusysid bench` gives for the same flight."""
    record = fleet.bench_task("figure8_3d", 1,
                              {"model": "rigid3d", "estimators": "linear"})
    assert record["status"] == "ok", record["error"]
    row = fleet._row(record)
    # IMU 0 of the 3-D scenarios (docs/simulator-3d.md), no misalignment.
    truth = {"x": 0.05, "y": -0.02, "z": -0.03}
    log = str(tmp_path / "F.ulg")
    code, _, err = cli("simulate", "--scenario=figure8_3d", "--seed=1",
                       f"--out={log}")
    assert code == 0, err
    code, out, err = cli("bench", "--models=rigid3d", "--estimators=linear",
                         f"--logs={log}", "--format=json")
    assert code == 0, err
    run = next(r for r in json.loads(out)["runs"] if r["instance"] == 0)
    for i, a in enumerate("xyz"):
        assert row[f"truth.{a}_m"] == pytest.approx(truth[a], abs=1e-15)
        assert row[f"error.{a}_m"] == pytest.approx(
            row[f"position.{a}_m"] - truth[a], abs=1e-15)
        # The tool's error of the same flight (seed 1, ULog): to rounding.
        assert row[f"error.{a}_m"] == pytest.approx(
            run["position_error_m"][i], abs=1e-12)
        assert row[f"stderr.{a}_m"] > 0 and row[f"given.{a}"] is True
        # A seed's error is a few σ̂ at most (σ̂ ~ 1 mm here).
        assert abs(row[f"error.{a}_m"]) < 5e-3
    # fleet fit of the same log finds the truth file beside it.
    fitted = fleet._row(fleet.fit_task(
        log, {"model": "rigid3d", "estimators": "linear"}))
    assert fitted["error.x_m"] == pytest.approx(row["error.x_m"], abs=1e-12)


def test_3d_truth_is_turned_into_the_imus_axes():
    """A sensor yawed 90° about down: its x axis is the body's y, so the
    body position (px, py, pz) is (py, −px, pz) in the IMU's axes."""
    truth = {"imus": [{"p_frd_m": [0.05, -0.02, -0.03],
                       "misalignment_deg": {"roll": 0.0, "pitch": 0.0,
                                            "yaw": 90.0}}]}
    turned = fleet._truth3d(truth, [{"instance": 0}])
    assert turned["x_m"] == pytest.approx(-0.02, abs=1e-15)
    assert turned["y_m"] == pytest.approx(-0.05, abs=1e-15)
    assert turned["z_m"] == pytest.approx(-0.03, abs=1e-15)


def test_3d_summary_gives_bias_spread_and_coverage_per_axis():
    rows = []
    # x errors 1, 3, −1 mm with σ̂ 1 mm, the last seed withholding x: the
    # bias and spread are over every seed, the coverage over the two that
    # give x (|e| ≤ 2σ̂ on one).
    for e_x, given in ((0.001, True), (0.003, True), (-0.001, False)):
        rows.append({"status": "ok", "scenario": "figure8_3d",
                     "model": "rigid3d", "estimator": "linear", "task_s": 0.1,
                     "error.x_m": e_x, "stderr.x_m": 0.001, "given.x": given})
    summary = fleet.summarize_bench(pd.DataFrame(rows))
    assert summary.loc[0, "seeds"] == 3
    assert summary.loc[0, "bias.x_m"] == pytest.approx(0.001)
    assert summary.loc[0, "sd.x_m"] == pytest.approx(0.002)
    assert summary.loc[0, "coverage.x_m"] == pytest.approx(0.5)
    assert summary.loc[0, "mean_stderr.x_m"] == pytest.approx(0.001)
    assert summary.loc[0, "given.x"] == 2
