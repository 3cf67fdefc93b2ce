"""Fit many flight logs, or many Monte Carlo seeds, on a Dask cluster.

    python3 -m imusysid.fleet fit LOGS... --out=results.csv
    python3 -m imusysid.fleet bench --preset=paper --seeds=1000 --out=DIR

Each log or seed is one task on a Dask distributed Client: a LocalCluster
of worker processes by default (--workers=N), or a running scheduler
(--scheduler=ADDR). Results go to a CSV (one row per task, flattened) and a
JSON-lines file beside it (the whole result per line, appended as each task
ends, so an interrupted run loses nothing). A task's key is a hash of its
input (the log's bytes, or the scenario and seed) and the options; keys
already in the output are skipped, so running the same command again
resumes. A failing task is a row with status "error" and the message; the
other tasks go on. docs/python.md.
"""

import argparse
import hashlib
import importlib
import json
import logging
import math
import os
import socket
import stat
import sys
import time

import imusysid

# Exit codes, as the imusysid tool's.
EXIT_OK = 0
EXIT_FAILED = 1
EXIT_BAD_INPUT = 2

# Scenarios each bench preset regenerates with seeds 1..N, as `imusysid
# bench --preset` picks its logs.
PRESET_SCENARIOS = {
    "paper": ["paper_test1", "paper_test2"],
    "ci": ["paper_test1", "paper_test2", "model_exact", "hover_only"],
    "ci3d": ["figure8_3d", "pitch_laps_3d"],
    "3d": ["figure8_3d", "pitch_laps_3d", "roll_laps_3d", "yaw_sweeps_3d"],
}

# Result keys left out of the CSV (they stay in the JSON lines): long text
# and per-estimator internals.
_CSV_SKIP = ("details", "trace", "message")


# Text quoted from the command line is cut to this many characters, as
# the tool cuts the fields it quotes.
_MAX_QUOTED = 40


class UsageError(Exception):
    """Bad command-line input: exit code 2."""


def _cut(text):
    text = str(text).encode("unicode_escape").decode("ascii")
    return text if len(text) <= _MAX_QUOTED else text[:_MAX_QUOTED] + "..."


def _file_kind(mode):
    """What a file that is not a regular one is, in the tool's words."""
    for test, kind in ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO"),
                       (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return kind
    return "not a regular file"


def read_input(path):
    """The bytes of the log at `path`, refused as the tool refuses an
    input: anything but a regular file (a device such as /dev/zero would
    never end, a FIFO could wait forever) and anything over the library's
    limit (kMaxInputFileBytes, 1 GiB), before it is read."""
    limit = imusysid._imusysid.MAX_INPUT_FILE_BYTES
    try:
        st = os.stat(path)
    except OSError as e:
        raise UsageError(f"cannot read '{path}': {e.strerror}") from e
    if not stat.S_ISREG(st.st_mode):
        raise UsageError(f"cannot read '{path}': it is "
                         f"{_file_kind(st.st_mode)}, not a regular file")
    if st.st_size > limit:
        raise UsageError(f"'{path}' is {st.st_size} bytes; inputs may hold "
                         f"at most {limit} bytes (docs/failure-modes.md)")
    try:
        with open(path, "rb") as f:
            content = f.read(limit + 1)
    except OSError as e:
        raise UsageError(f"cannot read '{path}': {e.strerror}") from e
    if len(content) > limit:  # it grew after the stat
        raise UsageError(f"'{path}' holds more than {limit} bytes; inputs "
                         "may hold at most that (docs/failure-modes.md)")
    return content


def check_output(path, what="this output is a pair of files"):
    """Refuses, before any work, an output the run could not write: it is
    written to a temporary file and renamed over the target, so the target
    must be a regular file (through symbolic links) or a new name in an
    existing folder that can be written. A device such as /dev/full would
    otherwise be read as earlier results, or replaced."""
    target = os.path.realpath(path)
    try:
        st = os.stat(target)
    except FileNotFoundError:
        st = None
    except OSError as e:
        raise UsageError(f"cannot write '{path}': {e.strerror}") from e
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise UsageError(f"cannot write '{path}': it is "
                         f"{_file_kind(st.st_mode)}, not a regular file "
                         f"({what})")
    folder = os.path.dirname(target) or "."
    if not os.path.isdir(folder):
        raise UsageError(f"cannot write '{path}': No such file or directory")
    if not os.access(folder, os.W_OK | os.X_OK) or (
            st is not None and not os.access(target, os.W_OK)):
        raise UsageError(f"cannot write '{path}': Permission denied")


def _import_dask():
    try:
        for name in ("distributed", "pandas"):
            importlib.import_module(name)
    except ImportError as e:
        raise UsageError(
            f"imusysid.fleet needs Dask distributed and pandas ({e}); on "
            "Debian: apt-get install python3-distributed python3-pandas "
            "python3-tqdm, and run them with the python3 that has them "
            "(/usr/bin/python3)") from e


def task_key(content, options):
    """The hash a task is known by: its input's bytes and its options."""
    h = hashlib.sha256()
    h.update(content)
    h.update(json.dumps(options, sort_keys=True).encode())
    return h.hexdigest()[:20]


def flatten(result):
    """A fit's JSON as one flat row: a nested object's keys as 'a.b'
    columns, lists and deeper objects as JSON text. A list of fits
    (several estimators or IMUs): the first, with n_results (the JSON
    lines keep them all)."""
    row = {}
    first = result[0] if isinstance(result, list) and result else result
    if isinstance(first, dict):
        for k, v in first.items():
            if k in _CSV_SKIP:
                continue
            if isinstance(v, dict):
                for k2, v2 in v.items():
                    row[f"{k}.{k2}"] = (json.dumps(v2)
                                        if isinstance(v2, (dict, list))
                                        else v2)
            elif isinstance(v, list):
                row[k] = json.dumps(v)
            else:
                row[k] = v
    row["n_results"] = len(result) if isinstance(result, list) else 1
    return row


def _worker_id():
    return f"{socket.gethostname()}:{os.getpid()}"


def _recorded(record, work):
    """Runs work(record, start) on a worker and returns `record` with its
    status: an error is recorded with its message and code, never raised, so
    that one bad task cannot lose the others."""
    start = time.perf_counter()
    try:
        work(record, start)
    except imusysid.Error as e:
        record.update(status="error", error=str(e), error_code=e.code)
    except Exception as e:  # a bug must not lose the other tasks
        record.update(status="error", error=f"{type(e).__name__}: {e}",
                      error_code="INTERNAL")
    record["task_s"] = time.perf_counter() - start
    return record


def _split_options(options):
    """(model, estimators, the other options) of a task's options."""
    options = dict(options)
    return options.pop("model", None), options.pop("estimators", None), options


def fit_task(path, options):
    """One log's fit, run on a worker: the result, or the error."""
    def work(record, start):
        model, estimators, rest = _split_options(options)
        record["result"] = imusysid.identify(path, model=model,
                                             estimators=estimators, **rest)
        truth = _truth_beside(path)
        if truth is not None and "imus" in truth:
            record["truth3d"] = _truth3d(truth, record["result"])

    return _recorded({"status": "ok", "error": "", "worker": _worker_id()},
                     work)


def bench_task(scenario, seed, options):
    """One Monte Carlo seed, run on a worker: the scenario flown with this
    noise seed (as `imusysid simulate --seed` writes it) and fitted with
    the same seed, beside the truth."""
    def work(record, start):
        model, estimators, rest = _split_options(options)
        # A 3-D scenario is flown as PX4 ULog (every IMU in one file).
        three_d = scenario.endswith("_3d")
        fmt = rest.pop("log_format", None) or ("ulog" if three_d else "csv")
        sim = imusysid.simulate(scenario, seed=seed, return_bytes=True,
                                format=fmt)
        record["sim_s"] = time.perf_counter() - start
        ext = {"ulog": "ulg", "dataflash": "bin"}.get(fmt, "csv")
        record["result"] = imusysid.identify(
            sim["bytes"][0], source=f"{scenario}.{ext} (seed {seed})",
            model=model, estimators=estimators, seed=seed, **rest)
        truth = sim["truth"]
        if "imus" in truth:
            record["truth3d"] = _truth3d(truth, record["result"])
        else:
            record["truth"] = {k: truth[k] for k in
                               ("r_m", "beta_deg", "alpha_deg", "mu",
                                "alpha_effective_deg") if k in truth}

    return _recorded({"scenario": scenario, "seed": seed, "status": "ok",
                      "error": "", "worker": _worker_id()}, work)


def _first(result):
    """A fit's first result object (a 3-D fit: its first IMU), or {}."""
    first = result[0] if isinstance(result, list) and result else result
    return first if isinstance(first, dict) else {}


def _truth_beside(path):
    """LOG.truth.json beside a log, as a dict; None without one."""
    truth_path = os.path.splitext(path)[0] + ".truth.json"
    if not os.path.isfile(truth_path):
        return None
    with open(truth_path, encoding="utf-8") as f:
        return json.load(f)


def _truth3d(truth, result):
    """The truth of a 3-D fit's first IMU in its own axes: R_sᵀ p with
    R_s = R_z(yaw) R_y(pitch) R_x(roll) the simulated misalignment, as
    `imusysid bench` turns it (benchmarks/bench3d.cc)."""
    instance, imus = _first(result).get("instance", 0), truth.get("imus") or []
    if not 0 <= instance < len(imus):
        return {}
    imu = imus[instance]
    m = imu.get("misalignment_deg") or {}
    r, q, y = (math.radians(m.get(k, 0.0)) for k in ("roll", "pitch", "yaw"))
    cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(q),
                              math.sin(q), math.cos(y), math.sin(y))
    rot = [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
           [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
           [-sp, cp * sr, cp * cr]]
    p = imu["p_frd_m"]  # R_sᵀ p: column i of R_s against p
    return {f"{a}_m": sum(rot[k][i] * p[k] for k in range(3))
            for i, a in enumerate("xyz")}


def _row3d(record, row):
    """A 3-D fit's first IMU per axis: position (every axis, given or
    withheld), σ̂, whether it is given, and against the truth."""
    first = _first(record["result"])
    fitted = first.get("fitted_position_frd_m") or [None] * 3
    stderr = first.get("imu_position_frd_stderr_m") or [None] * 3
    given = first.get("determined") or [None] * 3
    for i, a in enumerate("xyz"):
        row[f"position.{a}_m"] = fitted[i]
        row[f"stderr.{a}_m"] = stderr[i]
        row[f"given.{a}"] = given[i]
        truth = record.get("truth3d", {}).get(f"{a}_m")
        if truth is not None and fitted[i] is not None:
            row[f"truth.{a}_m"] = truth
            row[f"error.{a}_m"] = fitted[i] - truth


def _row(record):
    # The task's own fields first, and they win over the result's (its
    # "log" is the path the worker read; the row keeps the one given).
    row = {k: v for k, v in record.items()
           if k not in ("result", "truth", "truth3d")}
    if "result" in record:
        for k, v in flatten(record["result"]).items():
            row.setdefault(k, v)
        if "fitted_position_frd_m" in _first(record["result"]):
            _row3d(record, row)
    for k, v in record.get("truth", {}).items():
        row[f"truth.{k}"] = v
        est = row.get(k)
        if isinstance(est, (int, float)) and isinstance(v, (int, float)):
            row[f"error.{k}"] = est - v
    return row


def jsonl_path(csv_path):
    base, ext = os.path.splitext(csv_path)
    return (base if ext == ".csv" else csv_path) + ".jsonl"


def load_done(csv_path, retry_errors):
    """Records of earlier runs by key, from the JSON lines (the last line
    of a key wins) and else the CSV; without retry_errors every key counts
    as done, with it only those that succeeded."""
    import pandas as pd
    records = {}
    lines = jsonl_path(csv_path)
    if os.path.exists(lines):
        with open(lines, encoding="utf-8") as f:
            for n, line in enumerate(f, 1):
                line = line.strip()
                if not line:
                    continue
                try:
                    record = json.loads(line)
                except json.JSONDecodeError:
                    # A line cut short by a killed run: that task reruns.
                    print(f"fleet: {lines}:{n}: incomplete line skipped",
                          file=sys.stderr)
                    continue
                records[record["key"]] = record
    elif os.path.exists(csv_path):
        try:
            frame = pd.read_csv(csv_path, float_precision="round_trip")
        except (ValueError, OSError) as e:
            raise UsageError(f"{csv_path}: cannot read earlier results: {e}")
        if "key" not in frame.columns or "status" not in frame.columns:
            raise UsageError(f"{csv_path}: not a fleet result file (no key "
                             "and status columns); choose another --out")
        for row in frame.to_dict("records"):
            records[row["key"]] = {"flat": row, **row}
    if retry_errors:
        records = {k: r for k, r in records.items() if r["status"] == "ok"}
    return records


def _write_csv(records, csv_path):
    import pandas as pd
    rows = [r["flat"] if "flat" in r else _row(r) for r in records]
    frame = pd.DataFrame(rows)
    tmp = f"{csv_path}.tmp{os.getpid()}"
    frame.to_csv(tmp, index=False)
    os.replace(tmp, csv_path)
    return frame


def make_client(scheduler, workers):
    """A Client of the scheduler at ADDR, or of a LocalCluster of `workers`
    single-threaded worker processes (one fit each at a time)."""
    from distributed import Client, LocalCluster
    if scheduler:
        return Client(scheduler, timeout="30s")
    cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1,
                           threads_per_worker=1, processes=True,
                           dashboard_address=None,
                           silence_logs=logging.ERROR)
    return Client(cluster)


def run_tasks(tasks, csv_path, scheduler=None, workers=None, progress=True,
              retry_errors=False, client=None):
    """Runs the tasks not already in the output and writes the CSV and
    JSON lines. `tasks`: (key, function, args, fields) with fields the
    row's identity (log, scenario, seed). Returns the DataFrame of every
    row, old and new, and a dict of timing figures."""
    _import_dask()
    from distributed import as_completed
    try:
        from tqdm import tqdm
    except ImportError:  # no bar without tqdm
        tqdm = None
    done = load_done(csv_path, retry_errors)
    seen = set(done)
    todo = []
    for task in tasks:
        if task[0] not in seen:
            seen.add(task[0])
            todo.append(task)
    skipped = len(tasks) - len(todo)
    if skipped:
        print(f"fleet: {skipped} of {len(tasks)} tasks already in "
              f"{csv_path}; running {len(todo)}", file=sys.stderr)
    own_client = client is None
    timing = {"tasks": len(todo), "wall_s": 0.0, "task_s": 0.0,
              "workers": 0}
    records = dict(done)
    try:
        lines = open(jsonl_path(csv_path), "a", encoding="utf-8")
    except OSError as e:
        raise UsageError(f"{jsonl_path(csv_path)}: {e.strerror}") from e
    try:
        if todo:
            if own_client:
                client = make_client(scheduler, workers)
            timing["workers"] = len(client.scheduler_info()["workers"])
            start = time.perf_counter()
            futures = {}
            for key, function, args, fields in todo:
                future = client.submit(function, *args, key=f"imusysid-{key}",
                                       pure=False)
                futures[future] = (key, fields)
            bar = (tqdm(total=len(todo), unit="task", file=sys.stderr,
                        disable=not progress) if tqdm else None)
            for future in as_completed(futures):
                key, fields = futures[future]
                if future.status == "finished":
                    record = future.result()
                else:  # the worker died or the task could not run
                    error = future.exception()
                    record = {"status": "error", "error_code": "INTERNAL",
                              "error": f"{type(error).__name__}: {error}"}
                record = {"key": key, **fields, **record}
                future.release()
                lines.write(json.dumps(record) + "\n")
                lines.flush()
                records[key] = record
                timing["task_s"] += record.get("task_s", 0.0)
                if bar:
                    bar.update()
            if bar:
                bar.close()
            timing["wall_s"] = time.perf_counter() - start
    finally:
        lines.close()
        frame = _write_csv(list(records.values()), csv_path)
        if own_client and client is not None:
            cluster = getattr(client, "cluster", None)
            client.close()
            if cluster is not None:
                cluster.close()
    return frame, timing


def _overhead_text(timing):
    n, w = timing["tasks"], max(timing["workers"], 1)
    if not n:
        return "nothing to run"
    per_task = timing["task_s"] / n
    overhead = (timing["wall_s"] * w - timing["task_s"]) / n
    return (f"{n} tasks in {timing['wall_s']:.2f} s on {w} workers; mean "
            f"task {per_task * 1000:.0f} ms, scheduling and transfer "
            f"{overhead * 1000:.1f} ms per task")


def _fit_options(args):
    options = {"model": args.model, "threads": args.threads}
    if getattr(args, "seed", None) is not None:
        options["seed"] = args.seed
    if args.estimator:
        options["estimators"] = args.estimator
    if args.imu is not None:
        options["imu"] = args.imu
    return options


def command_fit(args):
    tasks = []
    options = _fit_options(args)
    outputs = {os.path.abspath(p) for p in (args.out, jsonl_path(args.out))}
    for path in (args.out, jsonl_path(args.out)):
        check_output(path)
    for path in args.logs:
        if os.path.abspath(path) in outputs:
            raise UsageError(f"{path} is both a log and the output")
        content = read_input(path)
        key = task_key(content, options)
        tasks.append((key, fit_task, (os.path.abspath(path), options),
                      {"log": path}))
    frame, timing = run_tasks(tasks, args.out, args.scheduler, args.workers,
                              not args.no_progress, args.retry_errors)
    print(f"fleet: {_overhead_text(timing)}; wrote {args.out} and "
          f"{jsonl_path(args.out)}", file=sys.stderr)
    return _exit_code(frame, args.strict)


def _exit_code(frame, strict):
    """0 once every task has its row: a task's failure is a result (its
    row says why). With strict, the tool's code for the failures: 2 when
    the library refused the input, else 1."""
    failed = frame[frame["status"] != "ok"] if not frame.empty else frame
    print(f"fleet: {len(frame) - len(failed)} ok, {len(failed)} failed",
          file=sys.stderr)
    if not strict or failed.empty:
        return EXIT_OK
    if set(failed["error_code"]) <= {"INVALID_ARGUMENT", "NOT_FOUND",
                                     "FAILED_PRECONDITION"}:
        return EXIT_BAD_INPUT
    return EXIT_FAILED


def summarize_bench(frame):
    """Bias, spread and usable count per scenario × model × estimator of
    the parameters the truth knows; for a 3-D model per axis also the
    seeds that give the axis (given.AXIS) and, over those, the share whose
    truth lies within ±2σ̂ (coverage.AXIS_m) and the mean σ̂."""
    import pandas as pd
    rows = []
    ok = frame[frame["status"] == "ok"]
    groups = ["scenario", "model", "estimator"]
    if ok.empty or not set(groups) <= set(ok.columns):
        return pd.DataFrame()
    for names, group in ok.groupby(groups):
        row = dict(zip(groups, names))
        row["seeds"] = len(group)
        row["mean_task_s"] = group["task_s"].mean()
        for column in group.columns:
            if column.startswith("error."):
                name = column[len("error."):]
                row[f"bias.{name}"] = group[column].mean()
                row[f"sd.{name}"] = group[column].std()
                if f"stderr.{name}" in group.columns:
                    # Over the seeds giving the axis, as the tool's table.
                    err = group[column].astype(float)
                    se = group[f"stderr.{name}"].astype(float)
                    known = err.notna() & se.notna()
                    given = f"given.{name[:-2]}"
                    if given in group.columns:
                        flags = group[given].astype(str) == "True"
                        row[given] = int(flags.sum())
                        known &= flags
                    row[f"coverage.{name}"] = (
                        (err[known].abs() <= 2 * se[known]).mean()
                        if known.any() else float("nan"))
                    row[f"mean_stderr.{name}"] = se[known].mean()
        rows.append(row)
    return pd.DataFrame(rows)


def command_bench(args):
    if args.preset not in PRESET_SCENARIOS:
        raise UsageError(f"--preset={_cut(args.preset)}; valid: "
                         f"{', '.join(PRESET_SCENARIOS)}")
    if args.seeds < 1:
        raise UsageError(f"--seeds={args.seeds}; required >= 1")
    scenarios = (args.scenarios.split(",") if args.scenarios
                 else PRESET_SCENARIOS[args.preset])
    valid = imusysid.scenario_names()
    for s in scenarios:
        if s not in valid:
            raise UsageError(f"--scenarios: unknown scenario '{_cut(s)}'; "
                             "valid: "
                             f"{', '.join(valid)}")
    options = _fit_options(args)  # each task fits with its noise seed
    if args.log_format:
        options["log_format"] = args.log_format
    tasks = []
    for scenario in scenarios:
        for seed in range(1, args.seeds + 1):
            content = json.dumps({"scenario": scenario, "seed": seed}).encode()
            tasks.append((task_key(content, options), bench_task,
                          (scenario, seed, options),
                          {"scenario": scenario, "seed": seed}))
    # Every output checked before any work: the folder, then its files.
    if os.path.exists(args.out) and not os.path.isdir(args.out):
        mode = os.stat(args.out).st_mode
        kind = "a regular file" if stat.S_ISREG(mode) else _file_kind(mode)
        raise UsageError(f"--out='{args.out}' is {kind}, not a folder "
                         "(bench writes monte_carlo.csv, "
                         "monte_carlo.jsonl, summary.csv and timing.json "
                         "into it)")
    try:
        os.makedirs(args.out, exist_ok=True)
    except OSError as e:
        raise UsageError(f"--out='{args.out}': cannot make the folder: "
                         f"{e.strerror}") from e
    csv_path = os.path.join(args.out, "monte_carlo.csv")
    for name in ("monte_carlo.csv", "monte_carlo.jsonl", "summary.csv",
                 "timing.json"):
        check_output(os.path.join(args.out, name), "bench replaces it")
    frame, timing = run_tasks(tasks, csv_path, args.scheduler, args.workers,
                              not args.no_progress, args.retry_errors)
    summary = summarize_bench(frame)
    summary_path = os.path.join(args.out, "summary.csv")
    summary.to_csv(summary_path, index=False)
    with open(os.path.join(args.out, "timing.json"), "w",
              encoding="utf-8") as f:
        json.dump(timing, f, indent=2)
    print(f"fleet: {_overhead_text(timing)}; wrote {csv_path}, "
          f"{jsonl_path(csv_path)} and {summary_path}", file=sys.stderr)
    return _exit_code(frame, args.strict)


def _add_common(parser):
    parser.add_argument("--scheduler", metavar="ADDR",
                        help="address of a running Dask scheduler "
                             "(tcp://host:8786); default: a local cluster")
    parser.add_argument("--workers", type=int, metavar="N",
                        help="worker processes of the local cluster "
                             "(default: one per CPU)")
    parser.add_argument("--model", help="model name (default: the "
                                        "library's choice per log)")
    parser.add_argument("--estimator", help="estimator name, or 'all' "
                                            "(default: the model's own)")
    parser.add_argument("--threads", type=int, default=1,
                        help="threads per fit (GA population; default 1: "
                             "the workers are the parallelism)")
    parser.add_argument("--imu", type=int, choices=(-1, 0, 1, 2),
                        help="IMU instance of the logs: 0, 1 or 2; -1: every "
                             "instance (3-D models, as imusysid.identify)")
    parser.add_argument("--retry-errors", action="store_true",
                        help="run again the tasks recorded as errors")
    parser.add_argument("--no-progress", action="store_true",
                        help="no progress bar")
    parser.add_argument("--strict", action="store_true",
                        help="exit non-zero when any task failed (2: the "
                             "library refused its input, 1: other)")


def build_parser():
    parser = argparse.ArgumentParser(
        prog="python3 -m imusysid.fleet",
        description="Fit many logs or Monte Carlo seeds on a Dask cluster; "
                    "results as CSV and JSON lines, resumable.",
        epilog="Exit status: 0 when every task has its row (a failed "
               "task's row says why; --strict: 2 or 1 then); 2 for bad "
               "input (a flag, a missing file, an unreadable --out).")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    fit = commands.add_parser(
        "fit", help="fit every log given, one task each",
        description="Fit every log given, one task each; one row per log "
                    "in --out (CSV) and its .jsonl beside it.")
    fit.add_argument("logs", nargs="+", metavar="LOG")
    fit.add_argument("--out", required=True, metavar="FILE.csv")
    fit.add_argument("--seed", type=int, default=1,
                     help="seed of the stochastic estimators")
    _add_common(fit)
    fit.set_defaults(run=command_fit)
    bench = commands.add_parser(
        "bench", help="Monte Carlo over noise seeds of simulated flights",
        description="Fly each scenario of the preset with noise seeds "
                    "1..SEEDS and fit each flight (one task per seed); "
                    "writes DIR/monte_carlo.csv (+ .jsonl), summary.csv "
                    "(bias and spread against the truth) and timing.json.")
    bench.add_argument("--preset", default="paper",
                       help="paper (paper_test1, paper_test2), ci (also "
                            "model_exact, hover_only), ci3d (figure8_3d, "
                            "pitch_laps_3d) or 3d (also roll_laps_3d, "
                            "yaw_sweeps_3d; with --model=rigid3d)")
    bench.add_argument("--scenarios",
                       help="comma-separated scenarios instead of the "
                            "preset's")
    bench.add_argument("--seeds", type=int, default=10)
    bench.add_argument("--log-format", choices=("csv", "ulog", "dataflash"),
                       help="log format (default: csv; 3-D scenarios ulog)")
    bench.add_argument("--out", required=True, metavar="DIR")
    _add_common(bench)
    bench.set_defaults(run=command_bench, model="consistent")
    return parser


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    if not args.command:
        parser.print_usage(sys.stderr)
        print("fleet: give a command: fit or bench", file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.workers is not None and args.workers < 1:
        print(f"fleet: --workers={args.workers}; required >= 1",
              file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.threads < 1:
        print(f"fleet: --threads={args.threads}; required >= 1",
              file=sys.stderr)
        return EXIT_BAD_INPUT
    try:
        _import_dask()
        return args.run(args)
    except UsageError as e:
        print(f"fleet: {e}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as e:
        # A write that failed after the checks (a full disk): one line, and
        # what finished is in the JSON lines.
        where = f"'{e.filename}': " if e.filename else ""
        print(f"fleet: cannot write {where}{e.strerror or e}",
              file=sys.stderr)
        return EXIT_FAILED
    except KeyboardInterrupt:
        print("fleet: interrupted; finished tasks are in the output, run "
              "the same command to resume", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
