"""Python interface to imusysid: read flight logs, simulate flights and fit
the IMU position with the C++ library's Identify.

Every fit returns plain Python data with the keys of
``imusysid fit --format=json``; log and simulator samples come as NumPy
arrays that view the library's memory. Errors raise :class:`Error` with the
library's message (naming the file and field). docs/python.md.
"""

import json
import math
import numbers
import os
import sys

try:
    from . import _imusysid
except ImportError as e:  # pragma: no cover - depends on the build
    raise ImportError(
        "imusysid: the compiled module _imusysid is missing from "
        f"{os.path.dirname(__file__)}: build it with cmake (target "
        "imusysid_python) or install the package (docs/python.md)") from e

#: The library's version (include/imusysid/version.h), as ``imusysid --version``
#: prints it.
__version__ = _imusysid.__version__

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
    "threads": ("threads: the GA population's evaluation, and a 3-D fit's "
                "IMU instances after the first, side by side (int)"),
    "max_time_s": "wall-time limit per estimator, s; 0: none",
    "covariance": "standard errors: 'hac' or 'white'",
    "use_measured_fz": "integrate velocity with the measured z force",
    "trace": "include the convergence trace",
    "estimator_options": "dict of named estimator options",
}
_LOG_OPTIONS = {
    "imu": "IMU instance (0, 1, 2; -1: every instance, 3-D models)",
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

# The IMU instances a log holds, and the one value that means all of them.
_IMU_INSTANCES = (0, 1, 2)
_ALL_IMUS = -1

# The gravity fit takes, m/s² (a problem file's range: the Moon's is 1.6,
# Jupiter's 24.8).
_MIN_GRAVITY = 0.1
_MAX_GRAVITY = 100.0

# Text quoted from an argument is cut to this many characters, as the
# tool cuts the fields it quotes.
_MAX_QUOTED = 40


# --- Argument checks. The tool takes its flags as text and checks each one
# (a number flag must be a finite number, an instance 0, 1 or 2, ...);
# Python arguments get the same checks, and a value of the wrong type is a
# TypeError rather than a conversion: text is not a number here, and a
# complex number is not a real one.

def _quote(value):
    """`value` as it may appear in a message: repr, control characters
    escaped by repr, cut to _MAX_QUOTED characters."""
    text = value if isinstance(value, str) else repr(value)
    text = text.encode("unicode_escape").decode("ascii")
    if len(text) > _MAX_QUOTED:
        text = text[:_MAX_QUOTED] + "..."
    return f"'{text}'"


def _invalid(message):
    """imusysid.Error with code INVALID_ARGUMENT, as the library raises."""
    error = Error(message)
    error.code = "INVALID_ARGUMENT"
    return error


def _type_name(value):
    return type(value).__name__


def _integer(name, value, allowed=None, low=None, high=None):
    """`value` as an int: an integer (Python's or NumPy's), not a bool,
    float or text; within `allowed` or [low, high]."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name}={_quote(value)}: an integer is required, "
                        f"not {_type_name(value)}")
    value = int(value)
    if allowed is not None and value not in allowed:
        raise _invalid(f"{name}={value}; required one of "
                       f"{', '.join(map(str, allowed))}")
    if (low is not None and value < low) or (high is not None
                                              and value > high):
        raise _invalid(f"{name}={value}; required in [{low}, {high}]")
    return value


def _real(name, value):
    """`value` as a finite float: a real number (int, float, NumPy's),
    not a bool, complex number or text; NaN and infinity are refused as
    the tool refuses them for a number flag."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}={_quote(value)}: a real number is "
                        f"required, not {_type_name(value)}")
    value = float(value)
    if not math.isfinite(value):
        raise _invalid(f"{name}={value}: the value must be a finite number")
    return value


def _boolean(name, value):
    numpy = sys.modules.get("numpy")
    if isinstance(value, bool) or (numpy is not None
                                   and isinstance(value, numpy.bool_)):
        return bool(value)
    raise TypeError(f"{name}={_quote(value)}: True or False is required, "
                    f"not {_type_name(value)}")


def _text(name, value):
    if not isinstance(value, str):
        raise TypeError(f"{name}={_quote(value)}: a str is required, not "
                        f"{_type_name(value)}")
    return value


def _path(name, value):
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{name}={_quote(value)}: a path (str or "
                        f"os.PathLike) is required, not {_type_name(value)}")
    path = os.fspath(value)
    if not isinstance(path, str):
        raise TypeError(f"{name}={_quote(value)}: a str path is required, "
                        f"not {_type_name(path)}")
    return path


def _imu(value, all_allowed):
    """An IMU instance: 0, 1 or 2, or -1 (every instance) where
    `all_allowed`."""
    imu = _integer("imu", value)
    if imu in _IMU_INSTANCES or (imu == _ALL_IMUS and all_allowed):
        return imu
    if imu == _ALL_IMUS:
        raise _invalid("imu=-1 (every instance) applies to identify with a "
                       "3-D model; this reads one instance: 0, 1 or 2")
    raise _invalid(f"imu={imu}; required 0, 1 or 2 (or -1, every "
                   "instance, for identify with a 3-D model)")


def _real_array(name, value, numpy):
    """`value` as a NumPy array of real numbers: integers or floats, not
    bools, complex numbers, text or objects (which a conversion to float64
    would change or drop silently)."""
    array = numpy.asarray(value)
    if array.dtype.kind not in "iuf":
        raise TypeError(f"{name}: an array of real numbers is required, not "
                        f"dtype {array.dtype}")
    return array


def _need_numpy(what):
    try:
        import numpy
    except ImportError as e:  # pragma: no cover - depends on the Python
        raise ImportError(f"imusysid.{what} needs NumPy") from e
    return numpy


# How each option identify and fit take is checked: the value's type and
# the tool's rule for its flag. The named strings (plane, velocity,
# covariance, frame) are checked by the library, which lists the valid
# ones.
_OPTION_CHECKS = {
    "seed": lambda v: _integer("seed", v, low=0, high=2**64 - 1),
    "threads": lambda v: _integer("threads", v, low=1, high=2**31 - 1),
    "max_time_s": lambda v: _real("max_time_s", v),
    "covariance": lambda v: _text("covariance", v),
    "use_measured_fz": lambda v: _boolean("use_measured_fz", v),
    "trace": lambda v: _boolean("trace", v),
    "frame": lambda v: _text("frame", v),
    "allow_damaged": lambda v: _boolean("allow_damaged", v),
    "plane": lambda v: _text("plane", v),
    "velocity": lambda v: _text("velocity", v),
    "cutoff_hz": lambda v: _real("cutoff_hz", v),
    "t_start": lambda v: _real("t_start", v),
    "t_end": lambda v: _real("t_end", v),
}


def _estimator_options(value):
    if not isinstance(value, dict):
        raise TypeError(f"estimator_options={_quote(value)}: a dict is "
                        f"required, not {_type_name(value)}")
    named = {}
    for key, v in value.items():
        _text("estimator_options key", key)
        if isinstance(v, (bool, str)):
            named[key] = v
        elif isinstance(v, numbers.Integral):
            named[key] = _integer(f"estimator_options[{key!r}]", v,
                                  low=-2**63, high=2**63 - 1)
        else:
            named[key] = _real(f"estimator_options[{key!r}]", v)
    return named


def _call_options(model, estimators, options, log_input):
    allowed = dict(_ESTIMATOR_OPTIONS)
    if log_input:
        allowed.update(_LOG_OPTIONS)
    unknown = sorted(set(options) - set(allowed))
    if unknown:
        raise TypeError(
            f"unknown option(s) {', '.join(_quote(u) for u in unknown)}; "
            f"valid: {', '.join(sorted(allowed))}")
    call = _imusysid.CallOptions()
    if model is not None:
        call.model = _text("model", model)
    if estimators == "all":
        call.all_estimators = True
    elif isinstance(estimators, str):
        call.estimators = [estimators]
    elif estimators is not None:
        if not isinstance(estimators, (list, tuple)):
            raise TypeError(f"estimators={_quote(estimators)}: a name, a "
                            "list of names or 'all' is required, not "
                            f"{_type_name(estimators)}")
        call.estimators = [_text("estimators", e) for e in estimators]
    for name, value in options.items():
        if value is None:
            continue
        if name == "estimator_options":
            call.named = _estimator_options(value)
        elif name == "imu":
            call.imu = _imu(value, all_allowed=True)
        else:
            setattr(call, name, _OPTION_CHECKS[name](value))
    return call


def scenario_names():
    """The simulator's scenarios: planar first, then 3-D (the library's
    own lists, ScenarioNames and Scenario3dNames)."""
    return list(_imusysid.scenario_names())


def read_log(path, imu=0, frame=None):
    """Read a flight log (CSV, PX4 ULog or ArduPilot DataFlash).

    Returns a dict: ``t``, ``ax``, ``ay``, ``az`` (m/s², FLU), ``gx``,
    ``gy``, ``gz`` (rad/s, FLU) as NumPy arrays viewing the library's log
    (no copy), ``channels`` (every other column by name), ``metadata``
    (list of (key, value)), ``parameters`` (the autopilot parameters the
    log records, list of (name, value)), ``source``, ``source_frame`` and
    ``reader_warnings``. ``imu``: the instance, 0, 1 or 2 (a log as
    arrays holds one; -1, every instance, is for :func:`identify`).
    """
    path = _path("path", path)
    imu = _imu(imu, all_allowed=False)
    frame = "" if frame is None else _text("frame", frame)
    return _imusysid.read_log(path, imu, frame)


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


def _one_log(log, call):
    """The log of a dict given as arrays: a read_log dict as it is; of a
    simulate result, the log of instance ``imu`` (default 0; a 3-D flight
    has one per IMU). The dict's own IMU is then the one fitted."""
    if "t" in log or "logs" not in log:
        return log
    logs = log["logs"]
    imu = call.imu
    if imu == _ALL_IMUS and len(logs) > 1:
        raise _invalid(
            f"imu=-1 (every instance): a log as arrays holds one IMU and "
            f"this flight has {len(logs)}; fit one (imu=0, 1 or 2), or the "
            "binary log with all (simulate(..., format='ulog', "
            "return_bytes=True)['bytes'][0])")
    index = 0 if imu in (None, _ALL_IMUS) else imu
    if index >= len(logs):
        raise _invalid(f"imu={imu}: the simulated flight has {len(logs)} "
                       f"IMU{'s' if len(logs) > 1 else ''}")
    call.imu = None
    return logs[index]


def _format_arrays(log, source, call):
    """The CSV text of a log given as arrays, for the library to read."""
    numpy = _need_numpy("identify (a log as arrays)")
    log = _one_log(log, call)
    source = source or log.get("source") or "<arrays>"
    columns = {k: _real_array(k, log[k], numpy)
               for k in _LOG_COLUMNS if k in log}
    channels = log.get("channels", {})
    if not isinstance(channels, dict):
        raise TypeError(f"channels: a dict of arrays is required, not "
                        f"{_type_name(channels)}")
    channels = {_text("channel name", k): _real_array(k, v, numpy)
                for k, v in channels.items()}
    frame = log.get("source_frame") or "flu"
    return source, _imusysid.format_log(
        source, columns, channels, list(log.get("metadata", [])),
        _text("source_frame", frame))


def identify(log, model=None, estimators=None, source=None, **options):
    """Fit a flight log; returns what ``imusysid fit --format=json`` prints.

    ``log`` is a path (str or os.PathLike), the log's bytes, or a log as
    arrays: a dict as :func:`read_log` returns (t, ax ... gz in FLU,
    optional channels, metadata and source_frame), or a :func:`simulate`
    result (its log of instance ``imu``, default 0); written to CSV text
    for the library (a copy) that reads back to the same numbers, so the
    fit is the file's. ``source`` names bytes or arrays in messages.
    ``model``: a registry name (default: the library's choice for the
    log). ``estimators``: a name, a list, or "all" (default: the model's
    own). Returns a dict (a list of dicts with several estimators, or for
    a 3-D fit of several IMUs), with one key the CLI does not print:
    ``parameters``, the physical parameters (r_m, beta_deg, ... as
    printed at the top level) in one dict. Options, as the CLI's flags
    and checked as it checks them: seed, threads, max_time_s, covariance,
    use_measured_fz, trace, estimator_options, imu (0, 1, 2, or -1: every
    instance, 3-D models), frame, allow_damaged, plane, velocity,
    cutoff_hz, t_start, t_end. The GIL is released while the fit runs.
    """
    call = _call_options(model, estimators, options, log_input=True)
    if source is not None:
        _text("source", source)
    if isinstance(log, dict):
        source, log = _format_arrays(log, source, call)
    if isinstance(log, (bytes, bytearray, memoryview)):
        text = _imusysid.identify(source or "<bytes>", bytes(log), call)
    elif isinstance(log, (str, os.PathLike)):
        text = _imusysid.identify(_path("log", log), None, call)
    else:
        raise TypeError(f"log={_quote(log)}: a path, bytes or a dict of "
                        f"arrays is required, not {_type_name(log)}")
    return _with_parameters(json.loads(text))


def fit(t, f_x, omega, omega_dot, v=None, f_z=None, theta=None,
        model=None, estimators=None, source="arrays", gravity=9.80665,
        **options):
    """Fit preprocessed planar samples as they are (no preprocessing).

    The arrays are the ProblemData fields (docs/problem-files.md): time
    ``t`` (s), ``f_x`` and ``f_z`` specific force (m/s²), ``omega`` pitch
    rate (rad/s), ``omega_dot`` (rad/s²), ``v`` horizontal velocity (m/s),
    ``theta`` pitch (rad): 1-D arrays of real numbers (a complex or text
    array is a TypeError), every sample finite. ``gravity`` in [0.1, 100]
    m/s², as a problem file's. They are copied once into the library. Returns
    the CLI's JSON keys (as :func:`identify`) plus ``estimate``,
    ``covariance`` (NumPy, every parameter including nuisance ones) and
    ``parameter_names``; a list of such dicts when several estimators ran.
    Options: seed, threads, max_time_s, covariance, trace,
    estimator_options.
    """
    call = _call_options(model, estimators, options, log_input=False)
    numpy = _need_numpy("fit")
    arrays = {}
    for name, value in (("t", t), ("f_x", f_x), ("omega", omega),
                        ("omega_dot", omega_dot), ("v", v), ("f_z", f_z),
                        ("theta", theta)):
        arrays[name] = (None if value is None
                        else _real_array(name, value, numpy))
    gravity = _real("gravity", gravity)
    if not _MIN_GRAVITY <= gravity <= _MAX_GRAVITY:
        # As a problem file's '# gravity:' line is checked: a typo such
        # as 9806.65 (mm/s²) or a sign would be fitted as a gravity.
        raise _invalid(f"gravity={gravity!r} is outside [0.1, 100] m/s^2; "
                       "expected the gravity in m/s^2, e.g. 9.80665")
    text, extra = _imusysid.fit(*arrays.values(), _text("source", source),
                                gravity, call)
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


def _setting_text(name, value):
    """A simulator setting as the text the library parses: numbers and
    bools given as such (text that reads as a number is refused, as
    everywhere here: its meaning would be a guess), names as str."""
    if isinstance(value, bool):
        return "true" if value else "false"
    numpy = sys.modules.get("numpy")
    if numpy is not None and isinstance(value, numpy.bool_):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return repr(_real(name, value))
    if isinstance(value, str):
        try:
            float(value)
        except ValueError:
            return value
        raise TypeError(f"{name}={_quote(value)}: give a number as a "
                        "number, not text")
    raise TypeError(f"{name}={_quote(value)}: a number, bool or str is "
                    f"required, not {_type_name(value)}")


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
    scenario = _text("scenario", scenario)
    if seed is not None:
        seed = _integer("seed", seed, low=0, high=2**64 - 1)
    format = "" if format is None else _text("format", format)
    frame = "" if frame is None else _text("frame", frame)
    return_bytes = _boolean("return_bytes", return_bytes)
    if out is not None:
        out = _path("out", out)
    values = {k: _setting_text(k, v) for k, v in settings.items()}
    logs, truth, images, three_d = _imusysid.simulate(
        scenario, seed, values, format, frame,
        out is not None or return_bytes)
    files = []
    if out is not None:
        if three_d and format in ("", "csv"):
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
