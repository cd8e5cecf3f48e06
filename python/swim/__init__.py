"""swim from Python: the simulator of an elastic swimmer in a 2D perfect fluid (libswim, by ctypes).

    import swim
    r = swim.run("models/example3.toml", t_end=5)
    r["t"], r["y"]                      # trajectory.csv's columns, as numpy arrays
    r.final_state                       # {"t": 5.0, "x": ..., "y": ..., "theta": ...}
    r.summary["energy_drift_rel"]       # summary.json, as a dict
    rows = swim.sweep("models/example3.toml", vary={"model.rho0": [0.5, 1.0, 2.0]}, t_end=5)
    m = swim.inspect(2, [1, 0, 0.2, -0.05, 0.1, 0.04])["mass_reduced"]
    with swim.Model("models/example3.toml", t_end=5) as model:   # read once, kernels loaded once
        for rho0 in (0.5, 1.0, 2.0):
            model.set("model.rho0", rho0)                       # a run-time key, in place
            r = model.run()

Every run is `swim run`'s run driver in this process: the same rows and the same summary as
`swim run` with the same overrides, bit for bit. docs/python.md is the reference.

Errors: swim.Error (status, message); swim.SceneError for bad input (file, line, key); a run that
fails (leaves the admissible set, an integrator gives up, ...) is not an exception: its Result has
completed False and the summary says why, so a loop over a family goes on past its failed members.

Keyword names: `overrides=` (alias `set=`) and `zipped=` (alias `zip=`); the aliases, which shadow
Python's builtins, keep working.
"""
import csv
import ctypes
import functools
import io
import itertools
import json
import math
import numbers
import os

import numpy as np

from . import _lib

OK, EFAILED, EINPUT, ENOMEM, EKERNEL = (_lib.SWIM_OK, _lib.SWIM_EFAILED, _lib.SWIM_EINPUT,
                                        _lib.SWIM_ENOMEM, _lib.SWIM_EKERNEL)

__all__ = ["run", "sweep", "spec_values", "inspect", "strerror", "Model", "Result", "Simulation", "Event", "Lyapunov",
           "periodic", "floquet", "continuation", "optimize", "Periodic", "Floquet", "Continuation", "Optimize",
           "Error", "SceneError",
           "KernelError", "LibraryNotFound", "OK", "EFAILED", "EINPUT", "ENOMEM", "EKERNEL", "MAX_MEMBERS",
           "__version__"]


class Error(Exception):
    """A call of libswim failed. .status is swim.h's (EFAILED, EINPUT, ENOMEM, EKERNEL), .message
    its one line of text."""

    def __init__(self, status, message, file=None, line=None, key=None):
        super().__init__(message)
        self.status = status
        self.message = message
        self.file = file
        self.line = line
        self.key = key


class SceneError(Error, ValueError):
    """Bad input (status EINPUT): a scene value, an override, an event, an argument of inspect.
    .file is the scene's name (None when the input is not a scene's), .line its line (None when
    not known: an override's value, a missing file), .key the key or the argument ("model.rho0", "shape")."""


class KernelError(Error):
    """No kernel could be had for the scene's structure (generation or compilation failed)."""


class LibraryNotFound(Error, ImportError):
    """No usable libswim.so (raised by `import swim`): none was found, or the one found is of
    another version (a function missing, or a struct whose size is not this package's mirror's:
    the message names the struct)."""


_L, _why = _lib.load()
if _L is None:
    raise LibraryNotFound(EFAILED, _why)

__version__ = _L.swim_version().decode()


def strerror(status):
    """The name of a status of libswim and what it means: strerror(EINPUT) is "SWIM_EINPUT: bad
    input (...)" (swim_strerror)."""
    return _L.swim_strerror(int(status)).decode()


def _alias(new, old, new_name, old_name):
    """The value of a keyword argument given by its name or by its older alias, not both."""
    if old is None:
        return new
    if new is not None:
        raise TypeError("swim: give %s= or its alias %s=, not both" % (new_name, old_name))
    return old


def _error(e):
    """The exception for a filled swim_error."""
    text = lambda b: b.decode("utf-8", "replace")
    cls = {EINPUT: SceneError, EKERNEL: KernelError}.get(e.status, Error)
    return cls(e.status, text(e.message), file=text(e.file) or None, line=e.line or None,
               key=text(e.key) or None)


# ---- overrides ------------------------------------------------------------------------------

def _c_text(text, key, file=None):
    """text as the bytes of a C string. A NUL inside would end the string there, silently (the
    scene "s.toml\\0junk" would be read as s.toml), so it is refused naming the key."""
    if "\0" in text:
        raise SceneError(EINPUT, "%s: the text holds a NUL character (at offset %d), which cannot be passed on"
                         % (key, text.index("\0")), file=file, key=key)
    return text.encode()


def _value_text(key, value):
    """VALUE of "KEY=VALUE" (the --set grammar): a float as repr, the shortest digits that read
    back to the same double; an int as an int (it stays one); a bool as TOML's; a word as is.
    NaN and the infinities are no value of any key: refused here, naming the key."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        if not math.isfinite(float(value)):
            raise SceneError(EINPUT, "%s: %r is not a finite number" % (key, float(value)), key=key)
        return repr(float(value))
    if isinstance(value, str):
        return value
    raise TypeError("swim: the value of %s must be a number, a bool or a word, not %r" % (key, value))


def _overrides(scene, overrides=None, **run_keys):
    """["KEY=VALUE", ...] of a dict of overrides and the run.* keyword arguments given (not None);
    a value refused here is a SceneError naming the key and the scene."""
    try:
        out = ["%s=%s" % (k, _value_text(k, v)) for k, v in (overrides or {}).items()]
        out += ["run.%s=%s" % (k, _value_text("run." + k, v)) for k, v in run_keys.items() if v is not None]
    except SceneError as e:
        e.file = _scene_name(scene)
        raise
    return out


def _scene_name(scene, name=None):
    """The name errors give a scene: its path, or `name` (default "(text)") for TOML text."""
    if isinstance(scene, os.PathLike) or "\n" not in scene:
        return os.fspath(scene)
    return name or "(text)"


def _c_strings(strings, key, file=None):
    """A char *[] of strings (kept alive by the returned array); key(s) names a string in errors."""
    arr = (ctypes.c_char_p * max(1, len(strings)))()
    for i, s in enumerate(strings):
        arr[i] = _c_text(s, key(s) if callable(key) else key, file)
    return arr


# ---- models ---------------------------------------------------------------------------------

class _Closing:
    """An object of the library freed by close(): in a with block, and by the garbage collector."""

    def close(self):
        pass

    def __del__(self):
        self.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class Model(_Closing):
    """A scene read and validated once, with its overrides and its kernels (swim_model): run it any
    number of times, changing run-time keys in place between runs with set().

        with swim.Model("models/example3.toml", t_end=5) as m:
            m.set("model.rho0", 2.0)     # as opening it with overrides={"model.rho0": 2.0}
            r = m.run()                  # a Result, bit for bit swim.run's

    scene, overrides (alias set), integrator, rtol, atol, t_end, output_step, name
                 as for run()
    m.columns    the names of the rows' columns (trajectory.csv's header)
    m.name       the scene's name in errors

    Raises SceneError for bad input and KernelError when no kernel can be had. Free it with
    close() or a with block (the garbage collector frees it too). One thread at a time.
    """

    def __init__(self, scene, overrides=None, integrator=None, rtol=None, atol=None, t_end=None,
                 output_step=None, name=None, *, set=None):
        self.ptr = None   # for close() when the scene is refused
        overrides = _alias(overrides, set, "overrides", "set")
        sets = _overrides(_scene_name(scene, name), overrides, integrator=integrator, rtol=rtol, atol=atol,
                          t_end=t_end, output_step=output_step)
        self._open(scene, sets, name)

    @classmethod
    def _with_sets(cls, scene, sets, name=None):
        """A model of ["KEY=VALUE", ...] already made (run() and sweep())."""
        m = cls.__new__(cls)
        m.ptr = None
        m._open(scene, sets, name)
        return m

    def _open(self, scene, sets, name):
        self.name = _scene_name(scene, name)
        self.text = None if isinstance(scene, os.PathLike) or "\n" not in scene else scene
        self.sets = list(sets)
        ptr, err = ctypes.c_void_p(), _lib.swim_error()
        arr = _c_strings(self.sets, lambda kv: kv.split("=", 1)[0], self.name)
        if self.text is None:
            rc = _L.swim_model_from_file(_c_text(self.name, "scene", self.name), arr, len(self.sets),
                                         ctypes.byref(ptr), ctypes.byref(err))
        else:
            rc = _L.swim_model_from_text(_c_text(self.text, "scene", self.name), _c_text(self.name, "name"), arr,
                                         len(self.sets), ctypes.byref(ptr), ctypes.byref(err))
        if rc != OK:
            raise _error(err)
        self.ptr = ptr
        names = ctypes.POINTER(ctypes.c_char_p)()
        ncol = _L.swim_model_columns(ptr, ctypes.byref(names))
        self.columns = tuple(names[i].decode() for i in range(ncol))

    def _live(self):
        if not self.ptr:
            raise ValueError("swim: the model %s is closed" % self.name)
        return self.ptr

    def set(self, key, value):
        """Set a run-time key in place, as opening the model with overrides={key: value} would
        (model.rho0, model.rhof, parameters.NAME, elastic.stiffness[I], damping.diagonal[I],
        barrier.alpha, shape.c0.am1, run.t_end, run.rtol, ...): the scene file is not read again
        and the kernels stay. A key that changes the kernel's structure (model.modes, shape.free,
        a stiffness made zero, ...) or a value the scene refuses raises SceneError naming the key;
        the model is then as it was (swim_model_set)."""
        text = _value_text(key, value)
        err = _lib.swim_error()
        if _L.swim_model_set(self._live(), _c_text(key, "key", self.name), _c_text(text, key, self.name),
                             ctypes.byref(err)) != OK:
            raise _error(err)

    def run(self, events=None, rows=True):
        """Run the model to its t_end (or a :stop event): a Result, as run() gives (events and
        rows as there)."""
        self._live()
        return _simulate(self, events, rows)

    def scene_text(self):
        """The scene as it will run, overrides and set() values written in (swim run's scene.toml)."""
        return _L.swim_model_scene_text(self._live()).decode()

    def close(self):
        """Free the model (its kernels and scene); a closed model cannot run. Called again: nothing."""
        if self.ptr and _L is not None:   # (at interpreter exit the module's globals may be gone)
            _L.swim_model_free(self.ptr)
            self.ptr = None

    def __repr__(self):
        return "<swim.Model %s%s>" % (self.name, "" if self.ptr else " (closed)")


# ---- rows -----------------------------------------------------------------------------------

class _Rows:
    """The rows of a run, copied as they come into a growing float64 array: one memmove per row,
    no Python float objects. The library's row is t followed by the other columns (its column
    names begin with "t"), so a row is copied whole."""

    def __init__(self, ncol):
        self.width = ncol
        self.n = 0
        self._grow(256)
        self.exception = None   # raised in the callback (e.g. KeyboardInterrupt): re-raised after the run
        self.fn = _lib.ROW_FN(self._row)

    def _grow(self, cap):
        old = getattr(self, "buf", None)
        self.buf = np.empty((cap, self.width))
        if old is not None:
            self.buf[:self.n] = old[:self.n]
        self.addr = self.buf.ctypes.data
        self.cap = cap

    def _row(self, ctx, t, values, ncol):
        # An exception must not cross into C (ctypes would print it and go on): keep it, stop the run.
        try:
            self._store(values, ncol)
            return 0
        except BaseException as e:
            self.exception = e
            return 1

    def _store(self, values, ncol):
        if self.n == self.cap:
            self._grow(2 * self.n)
        ctypes.memmove(self.addr + 8 * self.n * self.width, values, 8 * ncol)
        self.n += 1

    def array(self):
        return self.buf[:self.n].copy()


# ---- results --------------------------------------------------------------------------------

def _take_text(ptr):
    """The malloc'd C string at ptr, freed."""
    if not ptr:
        return None
    try:
        return ctypes.string_at(ptr).decode("utf-8", "replace")
    finally:
        _L.swim_free(ptr)


def _parse_events(text):
    """events.csv's rows (t,column,kind,value) as dicts, t and value as floats."""
    out = []
    for row in csv.DictReader(io.StringIO(text or "")):
        row["t"] = float(row["t"])
        row["value"] = float(row["value"])
        out.append(row)
    return out


class Result:
    """One run.

    r[name]        a column of the rows by trajectory.csv's name ("t", "x", "y", "theta", "am1",
                   ..., "energy", ...): a 1-D float64 array (a view of r.rows)
    r.columns      the names, "t" first (trajectory.csv's header, swim_model_columns)
    r.rows         every row: a 2-D float64 array, one row per output time (empty without rows)
    r.completed    True when the run reached t_end or a :stop event
    r.status, r.reason   summary.json's ("completed" / "failed", and why)
    r.final_state  {"t", "x", "y", "theta"}: the body's position where the run ended (exact doubles)
    r.state        the state there in trajectory.csv's layout x, y, theta, c, cdot (1-D array)
    r.summary      summary.json of the run as a dict
    r.events       the located events (events.csv): [{"t", "column", "kind", "value"}, ...]
    r.scene_text   the scene as run, overrides written in (swim run's scene.toml)
    """

    def __init__(self, columns, rows, result, state, summary, events, scene_text):
        self.columns = tuple(columns)
        self.rows = rows
        self._index = {c: i for i, c in enumerate(self.columns)}
        self.completed = bool(result.completed)
        self.final_state = {"t": result.t_reached, "x": result.x, "y": result.y, "theta": result.theta}
        self.state = state
        self._summary = summary   # a dict, or None until summary is asked for (_summary_text gives it)
        self._summary_text = None
        self.events = events
        self.scene_text = scene_text
        self.steps = result.steps
        self.rhs_evaluations = result.rhs_evaluations

    @property
    def summary(self):
        """summary.json of the run as a dict."""
        if self._summary is None:
            self._summary = json.loads(self._summary_text() or "{}")
            self._summary_text = None
        return self._summary

    @property
    def status(self):
        """summary.json's status: "completed" or "failed"."""
        return self.summary.get("status")

    @property
    def reason(self):
        """summary.json's reason: why the run ended as it did."""
        return self.summary.get("reason")

    def __getitem__(self, name):
        try:
            return self.rows[:, self._index[name]]
        except KeyError:
            raise KeyError("no column %r (columns: %s)" % (name, ", ".join(self.columns))) from None

    def __contains__(self, name):
        return name in self._index

    def keys(self):
        """The column names, as r.columns (so that dict(r) and pandas.DataFrame(dict(r)) work)."""
        return self.columns

    def __repr__(self):
        f = self.final_state
        return "<swim.Result %s at t = %r: x = %r, y = %r, theta = %r; %d rows>" % (
            self.status, f["t"], f["x"], f["y"], f["theta"], len(self.rows))


def _simulate(model, events=None, rows=True):
    """Run a model to its t_end (or a :stop event): a Result; raises only for bad input (events)."""
    events = list(events or [])
    collect = _Rows(len(model.columns)) if rows else None
    ev = _c_strings(events, "events", model.name)
    opts = _lib.swim_sim_options()
    if collect:
        opts.rows = collect.fn
    opts.events = ctypes.cast(ev, ctypes.POINTER(ctypes.c_char_p))
    opts.nevents = len(events)
    sim, err = ctypes.c_void_p(), _lib.swim_error()
    if _L.swim_sim_create(model.ptr, ctypes.byref(opts), ctypes.byref(sim), ctypes.byref(err)) != OK:
        raise _error(err)
    try:
        rc = _L.swim_sim_run(sim, ctypes.byref(err))
        if collect and collect.exception is not None:
            raise collect.exception
        if rc not in (OK, EFAILED):   # out of memory: no result worth returning
            raise _error(err)
        res = _lib.swim_result()
        _L.swim_sim_result(sim, ctypes.byref(res))
        state = np.empty(_L.swim_sim_state(sim, None, 0))   # asked for none, it says how many
        _L.swim_sim_state(sim, state.ctypes.data_as(_lib._PD), len(state))
        summary = json.loads(_take_text(_L.swim_sim_summary_json(sim)) or "{}")
        ev_rows = _parse_events(_take_text(_L.swim_sim_events_csv(sim)))
    finally:
        _L.swim_sim_free(sim)
    data = collect.array() if collect else np.empty((0, len(model.columns)))
    return Result(model.columns, data, res, state, summary, ev_rows, model.scene_text())


def run(scene, overrides=None, integrator=None, rtol=None, atol=None, t_end=None, output_step=None, events=None,
        name=None, rows=True, *, set=None):
    """Run a scene, as `swim run SCENE --set ...` does, and return its Result.

    scene        a scene file's path, or the TOML text itself (text when it holds a newline; its
                 errors then name it `name`, default "(text)")
    overrides    {"model.rho0": 2, "elastic.stiffness[4]": 3, "shape.c0.am1": 0.3, ...}
                 applied before the scene is validated (the --set grammar; models/README.md keys);
                 `set=` is its older alias
    integrator, rtol, atol, t_end, output_step
                 the run.* keys of the same names ("abm", "rk8pd", "cvode-bdf", ...)
    events       ["COLUMN:KIND[:stop]", ...] as `swim run --event` (KIND zero, min or max;
                 COLUMN any column but t), besides the scene's [events]
    rows         False: do not keep the rows (the summary is the same: every row is computed)

    Raises SceneError for bad input and KernelError when no kernel can be had; a run that fails
    returns its Result with completed False (r.reason says why).
    """
    overrides = _alias(overrides, set, "overrides", "set")
    sets = _overrides(_scene_name(scene, name), overrides, integrator=integrator, rtol=rtol, atol=atol, t_end=t_end,
                      output_step=output_step)
    with Model._with_sets(scene, sets, name) as model:
        return _simulate(model, events, rows)


# ---- families -------------------------------------------------------------------------------

def spec_values(spec):
    """The values of a `swim sweep --vary KEY=SPEC` SPEC, computed as swim sweep computes them (the
    same doubles): "START:STOP:COUNT" (linear, both endpoints exact), "log:START:STOP:COUNT" or
    "V1,V2,..."."""
    logarithmic = spec.startswith("log:")
    body = spec[4:] if logarithmic else spec
    if ":" not in body:
        return [float(v) for v in body.split(",")]
    parts = body.split(":")
    if len(parts) != 3:
        raise SceneError(EINPUT, "expected %sSTART:STOP:COUNT, got '%s'" % ("log:" if logarithmic else "", spec),
                         key="vary")
    try:
        a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise SceneError(EINPUT, "bad SPEC '%s' (START:STOP:COUNT: two numbers and an integer)" % spec,
                         key="vary") from None
    if not (1 <= n <= MAX_MEMBERS) or not (math.isfinite(a) and math.isfinite(b)) or \
            (logarithmic and not (a > 0 and b > 0)):
        raise SceneError(EINPUT, "bad SPEC '%s' (finite START, STOP; COUNT 1..%d; log: START, STOP > 0)"
                         % (spec, MAX_MEMBERS), key="vary")
    out = []
    for i in range(n):
        f = i / (n - 1) if n > 1 else 0.0
        out.append(math.exp(math.log(a) + f * (math.log(b) - math.log(a))) if logarithmic else a + f * (b - a))
    out[0] = a
    if n > 1:
        out[-1] = b
    return out


# The most members a family may have, as `swim sweep` (SWEEP_MAX_MEMBERS, runtime/sweep/sweep.h).
MAX_MEMBERS = 1000000


def _members(vary, zip_):
    """The varied keys, the member count, and a function giving a fresh iterator over the varied
    values of each member in id order: the Cartesian product of vary's lists (the last key varies
    fastest, as `swim sweep --vary`), or the lists paired with zip_. The count is bounded by
    MAX_MEMBERS before any member is made."""
    keys = list(vary)
    lists = []
    for k in keys:
        v = vary[k]
        if isinstance(v, str):
            lists.append(spec_values(v))
            continue
        try:
            n = len(v)
        except TypeError:
            raise SceneError(EINPUT, "%s: the values must be a list or a SPEC string, not %r" % (k, v), key=k) from None
        if n > MAX_MEMBERS:
            raise SceneError(EINPUT, "%s: %d values, more than the %d members a family may have" % (k, n, MAX_MEMBERS),
                             key=k)
        lists.append(np.asarray(v).tolist() if isinstance(v, np.ndarray) else list(v))
    if zip_:
        if len({len(v) for v in lists}) > 1:
            raise SceneError(EINPUT, "zip: the varied keys have different numbers of values (%s)" %
                             ", ".join("%s: %d" % (k, len(v)) for k, v in zip(keys, lists)), key="vary")
        count = len(lists[0]) if lists else 0
    else:
        count = 1
        for k, v in zip(keys, lists):
            count *= len(v)
            if count > MAX_MEMBERS:
                raise SceneError(EINPUT, "the grid has more than %d members" % MAX_MEMBERS, key=k)
    combos = (lambda: zip(*lists)) if zip_ else (lambda: itertools.product(*lists))
    return keys, count, lambda: (dict(zip(keys, c)) for c in combos())


def _path(d, *path):
    for p in path:
        if not isinstance(d, dict):
            return None
        d = d.get(p)
    return d


@functools.lru_cache(maxsize=None)
def _family_columns():
    """members.csv's columns after id, the varied keys, status and reason, with where a member's
    summary holds each (the library's table, swim_family_column: the one swim sweep writes)."""
    cols, i, path = [], 0, ctypes.c_char_p()
    while True:
        name = _L.swim_family_column(i, ctypes.byref(path))
        if name is None:
            return tuple(cols)
        cols.append((name.decode(), tuple(path.value.decode().split("."))))
        i += 1


def _member_row(i, values, r):
    """members.csv's row of a member (the same names and the same summary paths as swim sweep),
    with completed besides."""
    s = r.summary
    row = {"id": i}
    row.update(values)
    row.update({"status": s.get("status"), "completed": r.completed, "reason": s.get("reason")})
    row.update({name: _path(s, *path) for name, path in _family_columns()})
    return row


def _row_of_member(i, values, c):
    """_member_row from libswim's swim_member (the summary's numbers, read in C): null as None."""
    num = lambda v: None if v != v else v
    count = lambda v: None if v < 0 else v
    row = {"id": i}
    row.update(values)
    row.update({"status": c.status.decode("utf-8", "replace") or None, "completed": bool(c.completed),
                "reason": c.reason.decode("utf-8", "replace") or None, "t_reached": num(c.t_reached),
                "x": num(c.x), "y": num(c.y), "theta": num(c.theta), "energy_drift_rel": num(c.energy_drift_rel),
                "energy_balance_abs": num(c.energy_balance_abs), "jmin": num(c.jmin), "steps": count(c.steps),
                "rhs_evaluations": count(c.rhs_evaluations), "integrate_seconds": num(c.integrate_seconds),
                "wall_seconds": num(c.wall_seconds)})
    return row


def sweep(scene, vary, overrides=None, zipped=None, integrator=None, rtol=None, atol=None, t_end=None,
          output_step=None, events=None, results=False, threads=1, *, set=None, zip=None):
    """Run a family of a scene in this process, as `swim sweep` would: one member after another, or
    on `threads` threads at once.

    vary         {KEY: [values, ...] or "SPEC", ...} (SPEC as swim sweep's: "0.5:2:16",
                 "log:1e-3:1:4", "1,2,5"; spec_values): the members are the Cartesian product of the lists
                 (the last key varies fastest; member ids 0, 1, ... in that order), or with
                 zipped=True (alias zip=True) the lists paired (equal lengths)
    overrides (alias set), integrator, rtol, atol, t_end, output_step, events
                 as for run(), the same for every member
    results      True: each row also holds the member's Result under "result" (its rows kept)
    threads      K > 1: the members on K threads of this process (libswim runs without the GIL,
                 so K cores work at once); the rows are the same, bit for bit, in member-id order

    Returns one dict per member in id order, with members.csv's names: id, the varied keys,
    status, reason, t_reached, x, y, theta, energy_drift_rel, energy_balance_abs, jmin, steps,
    rhs_evaluations, integrate_seconds, wall_seconds (read from the member's summary at the paths
    swim sweep reads), and completed (a bool). Every member is loaded and validated before any
    runs: bad input raises SceneError naming the member ("member 1 (model.rho0=-1): ..."). A failed
    member is a row with completed False (also one whose run raised an error of the library:
    status "failed", reason its message); the family goes on. The member count is bounded first
    (MAX_MEMBERS, as swim sweep's). A model is opened once per thread and each member's varied keys
    are set in it (Model.set; a key that cannot be set in place, a structure key, opens a model for
    that member alone), so the scene is read and its kernels loaded once per thread, not per member.
    """
    overrides = _alias(overrides, set, "overrides", "set")
    zipped = bool(_alias(zipped, zip, "zipped", "zip"))
    fixed = _overrides(scene, overrides, integrator=integrator, rtol=rtol, atol=atol, t_end=t_end,
                       output_step=output_step)
    keys, _count, members = _members(vary, zipped)   # bounded, never listed
    fixed_keys = {s.split("=", 1)[0] for s in fixed}
    twice = [k for k in keys if k in fixed_keys]
    if twice:
        raise SceneError(EINPUT, "%s: both varied and set" % ", ".join(twice), key=twice[0])

    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral) or threads < 1:
        raise SceneError(EINPUT, "threads must be an integer >= 1, not %r" % (threads,), key="threads")
    threads = int(threads)

    def model(i, values):
        sets = _overrides(scene, values) + fixed
        try:
            return Model._with_sets(scene, sets)
        except Error as e:
            label = " ".join(sets[:len(values)])
            e.message = "member %d (%s): %s" % (i, label, e.message)
            e.args = (e.message,)
            raise

    # One model per thread, its varied keys set in place for each member (Model.set: bit for bit a
    # model opened with them, without reading the scene or loading kernels again); a member whose
    # keys cannot be set (a structure key) gets a model of its own. Every model is closed at the end.
    import threading
    local, opened = threading.local(), []

    spare = []   # models opened here, one per thread, before the threads start

    def model_for(i, values):
        """(model, whether it is the member's own, to be closed after it)."""
        m = getattr(local, "model", None)
        if m is None and spare:
            m = local.model = spare.pop()
        if m is not None and getattr(local, "settable", True):
            try:
                for k, v in values.items():
                    m.set(k, v)
                return m, False
            except SceneError:
                local.settable = False   # kept as it was; opening the member says whether it is bad
        own = model(i, values)
        if m is None:
            local.model = own
            opened.append(own)
            return own, False
        return own, True

    def check(i, values):
        try:
            m, own = model_for(i, values)
            if own:
                m.close()
        except Error as e:
            return e
        return None

    ev = _c_strings(list(events or []), "events", scene if isinstance(scene, str) else None)
    nev = len(events or [])

    def member_in_one_call(i, values):
        """The member on the thread's model in one call of libswim (swim_model_run_member: its keys
        set, the run, the summary's numbers; the GIL released throughout), or None when the thread
        has no model yet or its keys cannot be set in place."""
        m = getattr(local, "model", None)
        if m is None and spare:
            m = local.model = spare.pop()
        if m is None or not getattr(local, "settable", True):
            return None
        sets = _overrides(scene, values)
        arr = _c_strings(sets, lambda kv: kv.split("=", 1)[0], m.name)
        c, err = _lib.swim_member(), _lib.swim_error()
        rc = _L.swim_model_run_member(m.ptr, arr, len(sets), ev, nev, ctypes.byref(c), ctypes.byref(err))
        if rc == EINPUT and err.key.decode() in values:   # a structure key: a model of its own (below)
            local.settable = False
            return None
        if rc != OK:
            row = {"id": i}
            row.update(values)
            row.update({"status": "failed", "completed": False, "reason": _error(err).message})
            return row
        return _row_of_member(i, values, c)

    def member(i, values):
        if not results:
            row = member_in_one_call(i, values)
            if row is not None:
                return row
        try:
            m, own = model_for(i, values)
            try:
                r = _simulate(m, events, rows=results)
            finally:
                if own:
                    m.close()
        except Error as e:   # out of memory, a kernel gone since the check: a failed member, not the family's end
            row = {"id": i}
            row.update(values)
            row.update({"status": "failed", "completed": False, "reason": e.message})
            return row
        row = _member_row(i, values, r)
        if results:
            row["result"] = r
        return row

    def each(fn):
        if threads == 1:
            return [fn(i, values) for i, values in enumerate(members())]
        # the threads' models opened one after another here: threads opening the same kernel at
        # once would wait on its cache entry's lock
        spare[:] = opened   # the models of the threads of a pass before (none are in use)
        first = next(members(), None)
        while first is not None and len(spare) < min(threads, _count):
            try:
                m = model(0, first)
            except Error:
                break   # member 0 is bad: the check says so
            opened.append(m)
            spare.append(m)
        return _on_threads(fn, enumerate(members()), threads, _count)

    try:
        # every member validated before any runs; the first bad one by id is raised
        for e in each(check):
            if e is not None:
                raise e
        return each(member)
    finally:
        for m in opened:
            m.close()


def _on_threads(fn, items, threads, count):
    """[fn(*item) for item in items] on `threads` threads, in the items' order: each thread takes the
    next item (one at a time, so that a family of any length is never listed whole). The first
    exception (KeyboardInterrupt included) stops the others at their next item and is raised."""
    import threading
    out = [None] * count
    lock = threading.Lock()
    failed = []

    def work():
        while True:
            with lock:
                if failed:
                    return
                item = next(items, None)
            if item is None:
                return
            try:
                out[item[0]] = fn(*item)
            except BaseException as e:
                with lock:
                    failed.append(e)
                return

    pool = [threading.Thread(target=work, daemon=True) for _ in range(min(threads, max(1, count)))]
    for t in pool:
        t.start()
    for t in pool:
        t.join()
    if failed:
        raise failed[0]
    return out


# ---- inspection -----------------------------------------------------------------------------

def inspect(modes, shape, velocity=None, rho0=1.0, rhof=1.0, full=True):
    """The model's matrices at one shape, as `swim inspect` prints them.

    modes        N (0 .. 32); the shape has n = 2(N + 1) coordinates a1, b1, am1, bm1, ..., amN, bmN
    shape        n numbers (inside the admissible set D: min J > 0 on the unit circle, (4.1))
    velocity     n numbers, or None (then no christoffel_vv)
    rho0, rhof   densities of the body and of the fluid
    full         False: skip the whole Christoffel symbol (n^3 numbers)

    Returns a dict of float64 arrays: mass_rigid (3 x 3, Mr), mass_coupling (3 x n, N),
    mass_shape (n x n, Md), mass_reduced (n x n, K = Md - N^T Mr^-1 N), christoffel_vv (n,
    Gamma(c)(v, v); with a velocity), christoffel (n x n x n, Gamma^i_jk at [i, j, k]; with full),
    and jmin (a float). Raises SceneError naming the argument (key "shape", "velocity", "modes",
    "rho0", "rhof") for bad values, KernelError when no kernel of N modes can be had.
    """
    if isinstance(modes, bool) or not isinstance(modes, numbers.Integral):
        raise SceneError(EINPUT, "modes must be an integer, not %r" % (modes,), key="modes")
    n = 2 * (int(modes) + 1)

    def vector(name, v):
        a = np.ascontiguousarray(v, dtype=np.float64).reshape(-1)
        if a.size != n:
            raise SceneError(EINPUT, "%s has %d values; %d modes need n = 2(N + 1) = %d" % (name, a.size, modes, n),
                             key=name)
        return a

    c = vector("shape", shape) if modes >= 0 else np.zeros(0)
    v = vector("velocity", velocity) if velocity is not None else None
    out = {"mass_rigid": np.zeros((3, 3)), "mass_coupling": np.zeros((3, n)), "mass_shape": np.zeros((n, n)),
           "mass_reduced": np.zeros((n, n))}
    if v is not None:
        out["christoffel_vv"] = np.zeros(n)
    if full:
        out["christoffel"] = np.zeros((n, n, n))
    ptr = lambda a: a.ctypes.data_as(_lib._PD) if a is not None else None
    ins = _lib.swim_inspection(jmin=0.0, **{k: ptr(out.get(k)) for k in ("mass_rigid", "mass_coupling", "mass_shape",
                                                                          "mass_reduced", "christoffel_vv",
                                                                          "christoffel")})
    err = _lib.swim_error()
    if _L.swim_inspect(int(modes), ptr(c), ptr(v), float(rho0), float(rhof), ctypes.byref(ins), ctypes.byref(err)) != OK:
        raise _error(err)
    out["jmin"] = ins.jmin
    return out


# ---- a run to step through ------------------------------------------------------------------

from ._simulation import Event, Lyapunov, Simulation  # noqa: E402  (it builds on the names above)
from ._commands import Continuation, Floquet, Optimize, Periodic, continuation, floquet, optimize, periodic  # noqa: E402,F401
