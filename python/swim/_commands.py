"""swim.periodic, swim.floquet, swim.continuation and swim.optimize: the commands of the same names
as Python objects with their files' numbers.

Each calls libswim in this process (swim_periodic_orbit, swim_floquet_multipliers,
swim_continuation, swim_optimize), the GIL released while it computes: the JSON (and CSV) the
command would write comes from the same C writer, and the arrays (monodromy, multipliers, the
branch table, the best values) from the result structs."""
import csv
import io
import json

import numpy as np

import ctypes

from . import EINPUT, OK, SceneError, _L, _c_text, _lib, _value_text


def _numbers(v):
    """JSON values as numbers and arrays: a list of numbers (or of such lists) a float64 array, a
    list of {"re", "im", ...} a complex array, null NaN inside an array; dicts converted key by key."""
    if isinstance(v, dict):
        return {k: _numbers(x) for k, x in v.items()}
    if isinstance(v, list) and v:
        if all(isinstance(x, dict) and {"re", "im"} <= set(x) for x in v):
            return np.array([complex(x["re"], x["im"]) for x in v])
        try:
            a = np.array([np.nan if x is None else x for x in v] if not isinstance(v[0], list) else
                         [[np.nan if y is None else y for y in x] for x in v], dtype=np.float64)
            return a
        except (TypeError, ValueError):
            return [_numbers(x) for x in v]
    return v


class Output:
    """A command's JSON file: every entry as an attribute and by key (o.period, o["period"]), its
    lists of numbers as float64 arrays (matrices 2-D), complex numbers ({"re", "im"}) as complex
    arrays, null as None (NaN inside arrays). o.json is the file as json.load gives it."""

    def __init__(self, data, **more):
        self.json = data
        self._data = _numbers(data)
        self._data.update(more)

    def __getattr__(self, name):
        if name.startswith("_") or name == "json":
            raise AttributeError(name)
        try:
            return self._data[name]
        except KeyError:
            raise AttributeError("%s has no %r (it has: %s)" % (type(self).__name__, name,
                                                                ", ".join(self._data))) from None

    def __getitem__(self, name):
        return self._data[name]

    def __contains__(self, name):
        return name in self._data

    def keys(self):
        return self._data.keys()

    def __repr__(self):
        return "<swim.%s %s>" % (type(self).__name__, ", ".join(list(self._data)[:8]))


class Periodic(Output):
    """periodic.json of `swim periodic`: converged, reason, period, phase_point, displacement_per_period,
    newton (the iterations), floquet (the multipliers), ... (docs/control.md lists them)."""


class Floquet(Output):
    """floquet.json of `swim floquet`: the monodromy matrix (2-D array), the multipliers (complex
    array), periodic, stable, ... (docs/control.md)."""


class Continuation(Output):
    """branch.json of `swim continue`, and branch.csv as .table ({column: float64 array}) with
    .columns, its header."""


class Optimize(Output):
    """optimize.json of `swim optimize` (best values, the quantity, the searches), optimize.csv (the
    log of iterations) as .table ({column: array}) with .columns, and .best_values (the best values
    in vary's order, a float64 array)."""


def _csv_table(text):
    """A CSV text's header and {column: float64 array} (a column that is not numbers: an object array)."""
    rows = list(csv.reader(io.StringIO(text or "")))
    if not rows:
        return (), {}
    header, body = rows[0], rows[1:]
    table = {}
    for i, name in enumerate(header):
        col = [r[i] if i < len(r) else "" for r in body]
        try:
            table[name] = np.array([float(x) if x != "" else np.nan for x in col])
        except ValueError:
            table[name] = np.array(col, dtype=object)
    return tuple(header), table


def _orbit(kind, take, scene, overrides, section=None, tol=None, max_iter=None, t_max=None, param=None, start=None,
           stop=None, points=None):
    """One analysis of libswim (swim_periodic_orbit, swim_floquet_multipliers, swim_continuation) on
    the scene with its overrides: (the command's JSON as json.loads reads it, take(the result
    struct), which copies what it needs: the struct's arrays live with the C result, freed here).
    The GIL is released while it computes (ctypes)."""
    from . import Model, _error, _take_text
    o = _lib.swim_orbit_options()
    if section is not None:
        o.section = _c_text(section, "section")
    o.tol = 0.0 if tol is None else float(tol)
    o.max_iter = 0 if max_iter is None else int(max_iter)
    o.t_max = 0.0 if t_max is None else float(t_max)
    if param is not None:
        o.param = _c_text(param, "param")
        o.start, o.end = float(start), float(stop)
        o.points = 0 if points is None else int(points)
    entry, result, get = {"periodic": (_L.swim_periodic_orbit, _lib.swim_periodic_result, _L.swim_orbit_periodic),
                          "floquet": (_L.swim_floquet_multipliers, _lib.swim_floquet_result, _L.swim_orbit_floquet),
                          "continue": (_L.swim_continuation, _lib.swim_branch_result, _L.swim_orbit_branch)}[kind]
    with Model(scene, overrides) as m:
        ptr, err = ctypes.c_void_p(), _lib.swim_error()
        if entry(m.ptr, ctypes.byref(o), ctypes.byref(ptr), ctypes.byref(err)) != OK:
            raise _error(err)
        try:
            data = json.loads(_take_text(_L.swim_orbit_json(ptr)))
            r = result()
            get(ptr, ctypes.byref(r))
            return data, take(r)
        finally:
            _L.swim_orbit_free(ptr)


def _array(p, *shape):
    n = int(np.prod(shape))
    return np.ctypeslib.as_array(p, shape=(n,)).reshape(shape).copy() if p and n else np.empty(shape)


def _complex(re, im, n):
    return _array(re, n) + 1j * _array(im, n) if n else np.empty(0, dtype=complex)


def periodic(scene, overrides=None, guess_event=None, tol=None, max_iter=None, t_max=None, *, set=None):
    """A periodic orbit of the shape dynamics by Newton shooting, as `swim periodic` (docs/control.md):
    a Periodic with periodic.json's numbers (.converged, .period, .phase_point, .floquet, ...), and
    from the C result .monodromy (n x n) and .multipliers (the tangent ones, complex) when the orbit
    converged.

    overrides (alias set)  {KEY: value} as --set; guess_event "COLUMN:KIND"; tol, max_iter, t_max
    the command's --tol, --max-iter, --t-max. libswim's swim_periodic_orbit, in this process. Bad
    input raises SceneError; an orbit not found is a Periodic with converged False and the
    reason (exit_status 1, as the command's)."""
    def take(c):
        more = {"exit_status": 0 if c.converged else 1}
        if c.have_floquet:
            more["monodromy"] = _array(c.monodromy, c.n, c.n)
            more["multipliers"] = _complex(c.multipliers_re, c.multipliers_im, c.tangent_dimension)
        return more

    data, more = _orbit("periodic", take, scene, overrides if set is None else set, guess_event, tol, max_iter, t_max)
    return Periodic(data, **more)


def floquet(scene, overrides=None, event=None, t_max=None, *, set=None):
    """The monodromy matrix and Floquet multipliers of a periodic stroke, as `swim floquet`: a Floquet
    with floquet.json's numbers (.monodromy a 2-D array, the multipliers complex arrays, .periodic,
    .stable, ...). event "COLUMN:KIND" and t_max as the command's --event and --t-max. libswim's
    swim_floquet_multipliers, in this process; .monodromy and .multipliers (of M, complex) come
    from its C result."""
    def take(c):
        more = {"exit_status": 1 if c.stopped or not c.periodic else 0}
        if not c.stopped:
            more["monodromy"] = _array(c.monodromy, c.n, c.n)
            more["multipliers"] = _complex(c.multipliers_re, c.multipliers_im, c.n)
        return more

    data, more = _orbit("floquet", take, scene, overrides if set is None else set, event, None, None, t_max)
    return Floquet(data, **more)


def continuation(scene, param, start, stop, max_points=None, guess_event=None, tol=None, overrides=None, *, set=None):
    """A branch of periodic orbits in `param` ("energy" or a run-time key such as "model.rho0") from
    start to stop, as `swim continue --param PARAM=START:STOP`: a Continuation with branch.json's
    numbers and branch.csv as .table (a float64 array per column; "stable" as the words yes/no) and
    .columns. libswim's swim_continuation, in this process; the table is its C array."""
    def take(c):
        columns = tuple(c.names[j].decode() for j in range(c.columns))
        rows = _array(c.table, c.points, c.columns) if c.points else np.empty((0, c.columns))
        table = {name: rows[:, j].copy() for j, name in enumerate(columns)}
        if "stable" in table:
            table["stable"] = np.array(["yes" if v else "no" for v in table["stable"]], dtype=object)
        return {"table": table, "columns": columns, "exit_status": 1 if c.stopped or c.ended else 0}

    data, more = _orbit("continue", take, scene, overrides if set is None else set, guess_event, tol, None, None,
                        param, start, stop, max_points)
    return Continuation(data, **more)


def optimize(scene, vary, maximize=None, minimize=None, method=None, starts=None, max_iter=None, tol=None,
             overrides=None, *, set=None):
    """The best values of run-time keys within bounds for a quantity at t_end, as `swim optimize`:
    vary {KEY: (LO, HI)}, one of maximize / minimize a quantity (x, y, theta, displacement, work,
    forcing_work, displacement_per_work, energy), method "nelder-mead" or "bfgs", starts, max_iter,
    tol as the command's options. An Optimize with optimize.json's numbers ("best_scene" is None:
    no file is written), optimize.csv as .table and .columns, .best_values (the best values in
    vary's order, a float64 array, from the C result) and .exit_status (1 when not converged, as
    the command's). libswim's swim_optimize, in this process. Bad input raises SceneError naming
    the option or the key; no evaluation that succeeded raises Error."""
    from . import Model, _error, _take_text
    if (maximize is None) == (minimize is None):
        raise SceneError(EINPUT, "swim.optimize: give one of maximize= and minimize=", key="maximize")
    specs = ["%s=%s:%s" % (key, _value_text(key, lo), _value_text(key, hi)) for key, (lo, hi) in vary.items()]
    keep = [_c_text(v, "vary") for v in specs]
    o = _lib.swim_optimize_options()
    o.vary = (ctypes.c_char_p * max(1, len(keep)))(*keep)
    o.nvary = len(keep)
    o.quantity = _c_text(maximize if maximize is not None else minimize, "quantity")
    o.maximize = maximize is not None
    if method is not None:
        o.method = _c_text(method, "method")
    o.starts = 0 if starts is None else int(starts)
    o.max_iter = 0 if max_iter is None else int(max_iter)
    o.tol = 0.0 if tol is None else float(tol)
    with Model(scene, overrides if set is None else set) as m:
        ptr, err = ctypes.c_void_p(), _lib.swim_error()
        if _L.swim_optimize(m.ptr, ctypes.byref(o), ctypes.byref(ptr), ctypes.byref(err)) != OK:
            raise _error(err)
        try:
            data = json.loads(_take_text(_L.swim_orbit_json(ptr)))
            columns, table = _csv_table(_take_text(_L.swim_orbit_csv(ptr)))
            r = _lib.swim_optimize_result()
            _L.swim_orbit_optimize(ptr, ctypes.byref(r))
            best = _array(r.best, r.nkeys)
            exit_status = 0 if r.converged else 1
        finally:
            _L.swim_orbit_free(ptr)
    return Optimize(data, table=table, columns=columns, best_values=best, exit_status=exit_status)
