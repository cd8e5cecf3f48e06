"""swim.Simulation: one run to step through (swim_sim of libswim), with events delivered to Python,
dense output, sensitivities and the Lyapunov exponent. Public through swim/__init__.py."""
import ctypes
import json
import weakref

import numpy as np

from . import _lib
from . import (EFAILED, OK, Error, Model, Result, SceneError, EINPUT, _L, _alias, _c_strings, _c_text,  # noqa: F401
               _Closing, _error, _overrides, _parse_events, _Rows, _scene_name, _take_text)


class Event:
    """An event as it is located (swim_event): .t (also .time), .column ("am1"), .kind ("zero",
    "min" or "max"), .value (the column there) and .state (x, y, theta, c, cdot there: a float64
    array in the layout of Simulation.state)."""

    __slots__ = ("t", "column", "kind", "value", "state")

    def __init__(self, t, column, kind, value, state):
        self.t, self.column, self.kind, self.value, self.state = t, column, kind, value, state

    @property
    def time(self):
        return self.t

    def __repr__(self):
        return "<swim.Event %s:%s at t = %r, value %r>" % (self.column, self.kind, self.t, self.value)


class Lyapunov:
    """The Lyapunov pass of a run (summary.json's "lyapunov"): .exponent, .exponent_second_half,
    .verdict ("converged", "regular", "not_converged"), .horizon (inf: not within the run),
    .horizon_from_exponent, .interval, .t_end, .rtol, .computed (False: .reason says why), and per
    renormalization .t and .log_growth (float64 arrays)."""

    def __init__(self, r):
        self.computed = bool(r.computed)
        self.exponent = r.exponent
        self.exponent_second_half = r.exponent_second_half
        self.verdict = (r.verdict or b"").decode()
        self.horizon = r.horizon
        self.horizon_from_exponent = r.horizon_from_exponent
        self.interval, self.t_end, self.rtol = r.interval, r.t_end, r.rtol
        n = r.segments
        self.t = np.ctypeslib.as_array(r.t, (n,)).copy() if n > 0 else np.empty(0)
        self.log_growth = np.ctypeslib.as_array(r.log_growth, (n,)).copy() if n > 0 else np.empty(0)
        self.reason = (r.reason or b"").decode()

    def __repr__(self):
        return "<swim.Lyapunov exponent %r (%s), horizon %r>" % (self.exponent, self.verdict, self.horizon)


class Simulation(_Closing):
    """One run of a scene to step through, as heyoka's integrators or solve_ivp's dense output:

        sim = swim.Simulation("models/example3.toml", t_end=10, events=["am1:max"],
                              on_event=lambda e: e.column == "am1", sensitivity=["model.rho0"])
        sim.advance(2.0)          # the rows up to t = 2 (a float64 array); again to go on
        sim.t, sim.state          # where it is: the last row's time, x, y, theta, c, cdot there
        sim.state_at(1.99)        # the state anywhere in the integrator's last step
        r = sim.run()             # on to t_end: a Result, bit for bit swim.run's
        sim.sensitivity("y", "model.rho0")   # dy/d rho0 at every row (sensitivity.csv's column)
        sim.set("model.rho0", 2.0)           # a run-time key: the run starts again from t = 0

    scene, overrides (alias set), integrator, rtol, atol, t_end, output_step, name
                 as for swim.run()
    events       ["COLUMN:KIND[:stop]", ...] besides the scene's [events]
    on_event     called with an Event for every event as it is located; a true return stops the
                 run there (its last row is at the event; the run fails "stopped by the caller")
    sensitivity  a key or a list of keys of `swim run --sensitivity` ("model.rho0",
                 "parameters.A", "c0.am1", "initial", ...): computed when the run completes
    lyapunov     True (interval 1, as swim run) or an interval > 0: the Lyapunov exponent and
                 horizon when the run completes
    rows         False: the rows are not kept (advance() gives none, .rows is empty; .t, .state,
                 the summary and the events are the run's as with them), as swim.run(rows=False)

    Advancing in pieces gives the rows of one run bit for bit. Bad input raises SceneError before
    anything runs; a run that fails is not an exception (.completed False, .reason). Free it with
    close() or a with block. One thread at a time per Simulation; Simulations of their own run on
    threads at once (the library releases the GIL while it integrates).
    """

    def __init__(self, scene, overrides=None, integrator=None, rtol=None, atol=None, t_end=None, output_step=None,
                 events=None, on_event=None, sensitivity=None, lyapunov=False, name=None, rows=True, *, set=None):
        self._sim = None
        self._model = None
        overrides = _alias(overrides, set, "overrides", "set")
        sets = _overrides(_scene_name(scene, name), overrides, integrator=integrator, rtol=rtol, atol=atol,
                          t_end=t_end, output_step=output_step)
        if isinstance(sensitivity, str):
            sensitivity = [sensitivity]
        self._sens_keys = list(sensitivity or [])
        if lyapunov is True:
            lyapunov = 1.0
        self._lyapunov = float(lyapunov or 0.0)
        self._events = list(events or [])
        self._on_event = on_event
        self._model = Model._with_sets(scene, sets, name)
        self.columns = self._model.columns
        self.name = self._model.name
        self._keep_rows = bool(rows)
        # made once, used by every run of this simulation (set() and reset() start a new one)
        self._rows = _Rows(len(self.columns))
        self._ev = _c_strings(self._events, "events", self.name)
        self._event_fn = _lib.EVENT_FN(self._event)
        self._sens_text = _c_text(",".join(self._sens_keys), "sensitivity", self.name) if self._sens_keys else None
        self._pending = []   # weak references to Results whose summary is not read yet
        self._start()

    # ---- the C simulation ------------------------------------------------------------------

    def _start(self):
        """A fresh swim_sim of the model (at t = 0)."""
        self._free()
        self._rows.n = 0   # the rows handed out before were copies
        self._exception = None
        opts = _lib.swim_sim_options()
        if self._keep_rows:
            opts.rows = self._rows.fn
        opts.events = ctypes.cast(self._ev, ctypes.POINTER(ctypes.c_char_p))
        opts.nevents = len(self._events)
        if self._on_event is not None:
            opts.on_event = self._event_fn
        if self._sens_text is not None:
            opts.sensitivity = self._sens_text
        opts.lyapunov = self._lyapunov
        self._opts = opts   # the callbacks and strings live as long as the simulation
        sim, err = ctypes.c_void_p(), _lib.swim_error()
        if _L.swim_sim_create(self._model.ptr, ctypes.byref(opts), ctypes.byref(sim), ctypes.byref(err)) != OK:
            raise _error(err)
        self._sim = sim
        self._given = 0   # rows handed out by advance()
        self._t_asked = 0.0
        self._cache = None

    def _event(self, ctx, e):
        # An exception must not cross into C: keep it, stop the run, raise it after the call.
        try:
            ev = e.contents
            state = np.ctypeslib.as_array(ev.state, (ev.nstate,)).copy()
            event = Event(ev.t, ev.column.decode(), ev.kind.decode(), ev.value, state)
            return 1 if self._on_event(event) else 0
        except BaseException as x:
            self._exception = x
            return 1

    def _live(self):
        if not self._sim:
            raise ValueError("swim: the simulation of %s is closed" % self.name)
        return self._sim

    def _settle(self):
        """The summaries of the Results handed out, read now: the run is about to go on or to be
        freed, and a Result is the run as it was when it was made."""
        if self._pending:
            live = [r for r in (ref() for ref in self._pending) if r is not None and r._summary is None]
            self._pending = []
            if live:
                text = _take_text(_L.swim_sim_summary_json(self._sim))
                for r in live:
                    r._summary = json.loads(text or "{}")
                    r._summary_text = None

    def _call(self, fn, *args):
        self._settle()
        err = _lib.swim_error()
        rc = fn(self._live(), *args, ctypes.byref(err))
        self._cache = None
        for x in (self._rows.exception, self._exception):
            if x is not None:
                self._rows.exception = self._exception = None
                raise x
        if rc not in (OK, EFAILED):
            raise _error(err)
        return rc

    # ---- stepping --------------------------------------------------------------------------

    def advance(self, t):
        """The rows from where the last call stopped up to time t (every row at or before t), as a
        2-D float64 array (trajectory.csv's columns); called again, the run goes on. t before an
        earlier call's is a SceneError; beyond t_end the run stops at t_end."""
        t = float(t)
        self._call(_L.swim_sim_advance, ctypes.c_double(t))
        self._t_asked = max(self._t_asked, t)
        new = self._rows.buf[self._given:self._rows.n].copy()
        self._given = self._rows.n
        return new

    def run(self):
        """On to t_end (or a stopping event): the whole run's Result, as swim.run gives it."""
        self._call(_L.swim_sim_run)
        self._given = self._rows.n
        return self.result()

    def set(self, key, value):
        """Set a run-time key (model.rho0, parameters.NAME, elastic.stiffness[I], run.t_end, ...)
        in place, as swim.Model.set, and start the run again from t = 0 with it: rows, events and
        analyses begin anew, bit for bit those of a Simulation opened with that override. A
        structure key (model.modes, shape.free, ...) raises SceneError; the simulation is then
        as it was."""
        self._model.set(key, value)
        self._start()

    def reset(self):
        """Start the run again from t = 0 with the model as it is."""
        self._start()

    # ---- where it is -----------------------------------------------------------------------

    def _result(self):
        if self._cache is None:
            res = _lib.swim_result()
            _L.swim_sim_result(self._live(), ctypes.byref(res))
            self._cache = res
        return self._cache

    def _have_rows(self):
        return self._rows.n > 0 if self._keep_rows else self._result().rows > 0

    @property
    def t(self):
        """The time of the last row (0 before any)."""
        if not self._keep_rows:
            return self._result().t_reached if self._have_rows() else 0.0
        return self._rows.buf[self._rows.n - 1, 0] if self._rows.n else 0.0

    @property
    def state(self):
        """The state at the last row: x, y, theta, c, cdot (trajectory.csv's columns 1 .. 3 + 2n)."""
        n = _L.swim_sim_state(self._live(), None, 0)
        out = np.empty(n)
        if self._have_rows():
            _L.swim_sim_state(self._sim, out.ctypes.data_as(_lib._PD), n)
        else:
            out[:] = np.nan
        return out

    @property
    def rows(self):
        """Every row so far (a 2-D float64 array; a copy)."""
        return self._rows.array()

    def __getitem__(self, name):
        """A column of the rows so far by trajectory.csv's name."""
        try:
            return self._rows.buf[:self._rows.n, self.columns.index(name)].copy()
        except ValueError:
            raise KeyError("no column %r (columns: %s)" % (name, ", ".join(self.columns))) from None

    @property
    def finished(self):
        return bool(self._result().finished)

    @property
    def completed(self):
        return bool(self._result().completed)

    @property
    def summary(self):
        """summary.json of the run so far, as a dict."""
        return json.loads(_take_text(_L.swim_sim_summary_json(self._live())) or "{}")

    @property
    def reason(self):
        return self.summary.get("reason")

    @property
    def events(self):
        """The events located so far (events.csv): [{"t", "column", "kind", "value"}, ...]."""
        return _parse_events(_take_text(_L.swim_sim_events_csv(self._live())))

    def state_at(self, t):
        """The state at time t inside the integrator's last step (dense output: the interpolant the
        rows come from; a row's time gives that row's state bit for bit). A t outside that step is a
        SceneError naming the step; an integrator without dense output (rk8pd, msadams, rkf45,
        msbdf) has none (Error)."""
        n = _L.swim_sim_state(self._live(), None, 0)
        out = np.empty(n)
        err = _lib.swim_error()
        rc = _L.swim_sim_state_at(self._sim, float(t), out.ctypes.data_as(_lib._PD), n, ctypes.byref(err))
        if rc < 0:
            raise _error(err)
        return out

    def result(self):
        """The run so far as a Result (swim.run's: rows, summary, events, state)."""
        res = self._result()
        r = Result(self.columns, self._rows.array(), res, self.state, None, self.events, self._model.scene_text())
        # summary.json is made and parsed when it is asked for, or before the run goes on
        sim = self._sim
        r._summary_text = lambda: _take_text(_L.swim_sim_summary_json(sim))
        self._pending.append(weakref.ref(r))
        return r

    # ---- analyses --------------------------------------------------------------------------

    def _sens(self):
        names, ncol = ctypes.POINTER(ctypes.c_char_p)(), ctypes.c_int()
        values, nrows = _lib._PD(), ctypes.c_long()
        if not self._sens_keys:
            raise ValueError("swim: no sensitivity was asked for (Simulation(..., sensitivity=[KEY, ...]))")
        rc = _L.swim_sim_sensitivity(self._live(), ctypes.byref(names), ctypes.byref(ncol), ctypes.byref(values),
                                     ctypes.byref(nrows))
        if rc != OK and nrows.value == 0:
            raise Error(rc, "swim: no sensitivities: %s" % (self.reason if self.finished else
                                                           "the run has not completed yet (run() first)"))
        cols = [names[i].decode() for i in range(ncol.value)]
        data = np.ctypeslib.as_array(values, (nrows.value, ncol.value)).copy() if nrows.value else \
            np.empty((0, ncol.value))
        return cols, data

    @property
    def sensitivities(self):
        """Every column of sensitivity.csv by its name ("t", "dx/dmodel.rho0", "dy/dmodel.rho0",
        "dtheta/d...", "denergy/d...", "dwork/d...", "dam1/d...", "ddam1/d...") as float64
        arrays over the rows, once the run has completed: the numbers `swim run --sensitivity`
        writes."""
        cols, data = self._sens()
        return {c: data[:, i] for i, c in enumerate(cols)}

    def sensitivity(self, of, key):
        """d(of)/d(key) at every row: of is x, y, theta, energy, work, a coordinate (am1) or a
        velocity (dam1); key one of the sensitivity keys."""
        cols, data = self._sens()
        name = "d%s/d%s" % (of, key)
        if name not in cols:
            raise KeyError("no sensitivity %r (columns: %s)" % (name, ", ".join(cols)))
        return data[:, cols.index(name)]

    @property
    def lyapunov(self):
        """The Lyapunov pass (a Lyapunov) once the run has ended; None when none was asked for."""
        if not self._lyapunov:
            return None
        r = _lib.swim_lyapunov_result()
        _L.swim_sim_lyapunov(self._live(), ctypes.byref(r))
        return Lyapunov(r)

    @property
    def lyapunov_exponent(self):
        lyap = self.lyapunov
        return lyap.exponent if lyap else None

    @property
    def lyapunov_horizon(self):
        lyap = self.lyapunov
        return lyap.horizon if lyap else None

    # ---- life ------------------------------------------------------------------------------

    def _free(self):
        if self._sim and _L is not None:
            self._settle()
            _L.swim_sim_free(self._sim)
        self._sim = None

    def close(self):
        """Free the simulation and its model. Called again: nothing."""
        self._free()
        if self._model is not None:
            self._model.close()

    def __repr__(self):
        return "<swim.Simulation %s at t = %r%s>" % (self.name, self.t, "" if self._sim else " (closed)")
