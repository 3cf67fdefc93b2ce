"""Python interface to imusysid: read flight logs, simulate flights and fit
the IMU position with the C++ library's Identify.

Every fit returns plain Python data with the keys of
``imusysid fit --format=json``; log and simulator samples come as NumPy
arrays that view the library's memory. Errors raise :class:`Error` with the
library's message (naming the file and field). docs/python.md.
"""

import json
import os

try:
    from . import _imusysid
except ImportError as e:  # pragma: no cover - depends on the build
    raise ImportError(
        "imusysid: the compiled module _imusysid is missing from "
        f"{os.path.dirname(__file__)}: build it with cmake (target "
        "imusysid_python) or install the package (docs/python.md)") from e

__all__ = ["Error", "read_log", "simulate", "identify", "fit",
           "scenario_names"]

#: Raised for bad input or a failed fit; ``str(e)`` is the library's message
#: and ``e.code`` its status ("INVALID_ARGUMENT", "NOT_FOUND",
#: "FAILED_PRECONDITION", "IO_ERROR", "INTERNAL"). A subclass of ValueError.
Error = _imusysid.Error
Error.__module__ = __name__

# Options identify and fit take as keywords, with what each sets.
_ESTIMATOR_OPTIONS = {
    "seed": "noise seed of every stochastic estimator (int)",
    "threads": "threads evaluating the GA population (int)",
    "max_time_s": "wall-time limit per estimator, s; 0: none",
    "covariance": "standard errors: 'hac' or 'white'",
    "use_measured_fz": "integrate velocity with the measured z force",
    "trace": "include the convergence trace",
    "estimator_options": "dict of named estimator options",
}
_LOG_OPTIONS = {
    "imu": "IMU instance (0, 1, 2; -1: all, 3-D models)",
    "frame": "'flu' or 'frd': override a CSV's frame",
    "allow_damaged": "fit a log the reader had to repair",
    "plane": "'pitch' or 'roll'",
    "velocity": "'auto', 'gyro' or 'log'",
    "cutoff_hz": "low-pass cutoff, Hz",
    "t_start": "fit segment start, s",
    "t_end": "fit segment end, s",
}


# The arrays of a log as read_log returns them.
_LOG_COLUMNS = ("t", "ax", "ay", "az", "gx", "gy", "gz")


def scenario_names():
    """The simulator's scenarios: planar first, then 3-D."""
    return list(_imusysid.scenario_names())


def read_log(path, imu=0, frame=None):
    """Read a flight log (CSV, PX4 ULog or ArduPilot DataFlash).

    Returns a dict: ``t``, ``ax``, ``ay``, ``az`` (m/s², FLU), ``gx``,
    ``gy``, ``gz`` (rad/s, FLU) as NumPy arrays viewing the library's log
    (no copy), ``channels`` (every other column by name), ``metadata``
    (list of (key, value)), ``parameters`` (the autopilot parameters the
    log records, list of (name, value)), ``source``, ``source_frame`` and
    ``reader_warnings``.
    """
    return _imusysid.read_log(os.fspath(path), int(imu), frame or "")


def _call_options(model, estimators, options, log_input):
    allowed = dict(_ESTIMATOR_OPTIONS)
    if log_input:
        allowed.update(_LOG_OPTIONS)
    unknown = sorted(set(options) - set(allowed))
    if unknown:
        raise TypeError(
            f"unknown option(s) {', '.join(unknown)}; valid: "
            f"{', '.join(sorted(allowed))}")
    call = _imusysid.CallOptions()
    if model:
        call.model = model
    if estimators == "all":
        call.all_estimators = True
    elif isinstance(estimators, str):
        call.estimators = [estimators]
    elif estimators:
        call.estimators = list(estimators)
    for name, value in options.items():
        if value is None:
            continue
        if name == "estimator_options":
            call.named = dict(value)
        elif name == "frame":
            call.frame = str(value)
        else:
            setattr(call, name, value)
    return call


def _with_parameters(result):
    """Adds ``parameters``: the physical parameters (the top-level keys the
    CLI prints them under, null where withheld) as one dict. The keys come
    from the result itself: those of ``raw_parameters`` printed at the top
    level (nuisance terms are not)."""
    fits = result if isinstance(result, list) else [result]
    for one in fits:
        raw = one.get("raw_parameters") if isinstance(one, dict) else None
        if isinstance(raw, dict):
            one["parameters"] = {k: one[k] for k in raw if k in one}
    return result


def identify(log, model=None, estimators=None, source=None, **options):
    """Fit a flight log; returns what ``imusysid fit --format=json`` prints.

    ``log`` is a path (str or os.PathLike), the log's bytes, or a log as
    arrays (a dict as :func:`read_log` and :func:`simulate` return: t,
    ax ... gz in FLU, optional channels and metadata; written to CSV
    text for the library, a copy); ``source`` names bytes or arrays in
    messages. ``model``: a registry name (default:
    the library's choice for the log). ``estimators``: a name, a list, or
    "all" (default: the model's own). Returns a dict (a list of dicts with
    several estimators, or for a 3-D fit of several IMUs), with one key
    the CLI does not print: ``parameters``, the physical parameters
    (r_m, beta_deg, ... as printed at the top level) in one dict.
    Options, as the CLI's flags: seed, threads, max_time_s, covariance,
    use_measured_fz, trace, estimator_options, imu, frame, allow_damaged,
    plane, velocity, cutoff_hz, t_start, t_end. The GIL is released
    while the fit runs.
    """
    call = _call_options(model, estimators, options, log_input=True)
    if isinstance(log, dict):
        source = source or log.get("source") or "<arrays>"
        log = _imusysid.format_log(
            source, {k: log[k] for k in _LOG_COLUMNS if k in log},
            dict(log.get("channels", {})), list(log.get("metadata", [])))
    if isinstance(log, (bytes, bytearray, memoryview)):
        text = _imusysid.identify(source or "<bytes>", bytes(log), call)
    else:
        text = _imusysid.identify(os.fspath(log), None, call)
    return _with_parameters(json.loads(text))


def fit(t, f_x, omega, omega_dot, v=None, f_z=None, theta=None,
        model=None, estimators=None, source="arrays", gravity=9.80665,
        **options):
    """Fit preprocessed planar samples as they are (no preprocessing).

    The arrays are the ProblemData fields (docs/problem-files.md): time
    ``t`` (s), ``f_x`` and ``f_z`` specific force (m/s²), ``omega`` pitch
    rate (rad/s), ``omega_dot`` (rad/s²), ``v`` horizontal velocity (m/s),
    ``theta`` pitch (rad). They are copied once into the library. Returns
    the CLI's JSON keys (as :func:`identify`) plus ``estimate``,
    ``covariance`` (NumPy, every parameter including nuisance ones) and
    ``parameter_names``; a list of such dicts when several estimators ran.
    Options: seed, threads, max_time_s, covariance, trace,
    estimator_options.
    """
    call = _call_options(model, estimators, options, log_input=False)
    text, extra = _imusysid.fit(t, f_x, omega, omega_dot, v, f_z, theta,
                                source, float(gravity), call)
    result = _with_parameters(json.loads(text))
    fits = result if isinstance(result, list) else [result]
    for one, more in zip(fits, extra):
        one["estimate"] = more["estimate"]
        one["covariance"] = more["covariance"]
        one["parameter_names"] = more["names"]
    return result


def _truth_path(out):
    for ext in (".csv", ".ulg", ".bin"):
        if out.endswith(ext):
            return out[:-len(ext)] + ".truth.json"
    return out + ".truth.json"


def _imu_path(out, instance):
    if instance == 1:
        return out
    base = out[:-4] if out.endswith(".csv") and len(out) > 4 else out
    return f"{base}.imu{instance}.csv"


def simulate(scenario="paper_test1", seed=None, out=None, format="csv",
             frame=None, return_bytes=False, **settings):
    """Fly a simulator scenario (planar or 3-D, :func:`scenario_names`).

    ``settings``: planar scenarios take any simulator setting by name
    (``imusysid simulate --list_settings``), 3-D ones ``rate_hz`` and
    ``sensor_profile``. ``format``: "csv" (planar; 3-D also "ulog" or
    "dataflash"). With ``out`` the log and its truth sidecar are written
    as ``imusysid simulate --out`` writes them (a 3-D CSV: one file per
    IMU). Returns a dict: ``logs`` (one dict of NumPy arrays per IMU, as
    :func:`read_log`, viewing the simulator's memory), ``log`` (the
    first), ``truth`` (the sidecar as a dict), ``files`` (paths written)
    and ``three_d``; with ``return_bytes`` also ``bytes``, the file
    images (what :func:`identify` takes without a file).
    """
    values = {k: (str(v).lower() if isinstance(v, bool) else repr(v)
                  if isinstance(v, float) else str(v))
              for k, v in settings.items()}
    logs, truth, images, three_d = _imusysid.simulate(
        scenario, seed, values, format or "", frame or "",
        out is not None or return_bytes)
    files = []
    if out is not None:
        out = os.fspath(out)
        if three_d and format in (None, "csv"):
            targets = [_imu_path(out, k + 1) for k in range(len(images))]
        else:
            targets = [out]
        truth_path = _truth_path(out)
        _imusysid.write_file(truth_path, truth.encode())
        files.append(truth_path)
        for path, image in zip(targets, images):
            _imusysid.write_file(path, image)
            files.append(path)
    result = {"logs": logs, "log": logs[0], "truth": json.loads(truth),
              "files": files, "three_d": three_d}
    if return_bytes:
        result["bytes"] = list(images)
    return result
