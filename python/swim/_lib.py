"""libswim through ctypes: finding the shared library, and swim.h's types and prototypes.

Nothing here is public; swim/__init__.py builds the API on it. The structures mirror
runtime/lib/swim.h field for field; each starts with its size, set on creation, and at load their
sizes are compared with the library's (swim_struct_size), so a mirror that no longer matches is an
ImportError naming the struct, never wrong numbers.
"""
import ctypes
import glob
import os
import shutil

SWIM_OK, SWIM_EFAILED, SWIM_EINPUT, SWIM_ENOMEM, SWIM_EKERNEL = 0, 1, 2, 3, 4

# swim.h's SWIM_ABI, the number of the SONAME libswim.so.ABI these mirrors and prototypes are
# written against (tests/test_library_install.sh checks that the two agree).
ABI = 1
SONAME = "libswim.so.%d" % ABI


class _Sized(ctypes.Structure):
    """A struct of swim.h that starts with `size_t size`: set to its sizeof on creation, as the
    C initialisers SWIM_*_INIT do."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.size = ctypes.sizeof(self)


class swim_error(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("status", ctypes.c_int),
                ("file", ctypes.c_char * 1024),
                ("line", ctypes.c_int),
                ("key", ctypes.c_char * 128),
                ("message", ctypes.c_char * 2048)]


ROW_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_double,
                          ctypes.POINTER(ctypes.c_double), ctypes.c_int)


class swim_event(_Sized):
    """Filled by the library (its size is the library's): the fields read are the ones here."""
    _fields_ = [("size", ctypes.c_size_t),
                ("t", ctypes.c_double),
                ("column", ctypes.c_char_p),
                ("kind", ctypes.c_char_p),
                ("value", ctypes.c_double),
                ("state", ctypes.POINTER(ctypes.c_double)),
                ("nstate", ctypes.c_int)]


EVENT_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.POINTER(swim_event))


class swim_sim_options(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("rows", ROW_FN),
                ("rows_ctx", ctypes.c_void_p),
                ("events", ctypes.POINTER(ctypes.c_char_p)),
                ("nevents", ctypes.c_int),
                ("stop", ctypes.POINTER(ctypes.c_int)),
                ("on_event", EVENT_FN),
                ("event_ctx", ctypes.c_void_p),
                ("sensitivity", ctypes.c_char_p),
                ("lyapunov", ctypes.c_double)]


class swim_result(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("finished", ctypes.c_int),
                ("completed", ctypes.c_int),
                ("t_reached", ctypes.c_double),
                ("rows", ctypes.c_long),
                ("x", ctypes.c_double),
                ("y", ctypes.c_double),
                ("theta", ctypes.c_double),
                ("energy_initial", ctypes.c_double),
                ("energy_drift_abs", ctypes.c_double),
                ("energy_drift_rel", ctypes.c_double),
                ("jmin", ctypes.c_double),
                ("steps", ctypes.c_long),
                ("rhs_evaluations", ctypes.c_long)]


_PD = ctypes.POINTER(ctypes.c_double)


class swim_inspection(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("jmin", ctypes.c_double),
                ("mass_rigid", _PD),
                ("mass_coupling", _PD),
                ("mass_shape", _PD),
                ("mass_reduced", _PD),
                ("christoffel_vv", _PD),
                ("christoffel", _PD)]


class swim_lyapunov_result(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("computed", ctypes.c_int),
                ("exponent", ctypes.c_double),
                ("exponent_second_half", ctypes.c_double),
                ("verdict", ctypes.c_char_p),
                ("horizon", ctypes.c_double),
                ("horizon_from_exponent", ctypes.c_double),
                ("interval", ctypes.c_double),
                ("t_end", ctypes.c_double),
                ("rtol", ctypes.c_double),
                ("segments", ctypes.c_int),
                ("t", _PD),
                ("log_growth", _PD),
                ("reason", ctypes.c_char_p)]


class swim_orbit_options(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("section", ctypes.c_char_p),
                ("tol", ctypes.c_double),
                ("max_iter", ctypes.c_int),
                ("t_max", ctypes.c_double),
                ("stop", ctypes.POINTER(ctypes.c_int)),
                ("param", ctypes.c_char_p),
                ("start", ctypes.c_double),
                ("end", ctypes.c_double),
                ("points", ctypes.c_int)]


_NAMES = ctypes.POINTER(ctypes.c_char_p)


class swim_periodic_result(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("converged", ctypes.c_int),
                ("stopped", ctypes.c_int),
                ("reason", ctypes.c_char_p),
                ("iterations", ctypes.c_int),
                ("period", ctypes.c_double),
                ("residual", ctypes.c_double),
                ("state_scale", ctypes.c_double),
                ("dx", ctypes.c_double),
                ("dy", ctypes.c_double),
                ("dtheta", ctypes.c_double),
                ("energy", ctypes.c_double),
                ("energy_target", ctypes.c_double),
                ("t_guess", ctypes.c_double),
                ("period_guess", ctypes.c_double),
                ("n", ctypes.c_int),
                ("names", _NAMES),
                ("phase_point", _PD),
                ("have_floquet", ctypes.c_int),
                ("monodromy", _PD),
                ("tangent_dimension", ctypes.c_int),
                ("multipliers_re", _PD),
                ("multipliers_im", _PD),
                ("stable", ctypes.c_int),
                ("rhs_evaluations", ctypes.c_long),
                ("seconds", ctypes.c_double)]


class swim_floquet_result(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("stopped", ctypes.c_int),
                ("period", ctypes.c_double),
                ("t_first", ctypes.c_double),
                ("closure", ctypes.c_double),
                ("closure_relative", ctypes.c_double),
                ("periodic", ctypes.c_int),
                ("stable", ctypes.c_int),
                ("n", ctypes.c_int),
                ("monodromy", _PD),
                ("multipliers_re", _PD),
                ("multipliers_im", _PD),
                ("tangent_dimension", ctypes.c_int),
                ("tangent_re", _PD),
                ("tangent_im", _PD),
                ("complement_dimension", ctypes.c_int),
                ("complement_re", _PD),
                ("complement_im", _PD),
                ("rhs_evaluations", ctypes.c_long),
                ("seconds", ctypes.c_double)]


class swim_branch_result(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("stopped", ctypes.c_int),
                ("points", ctypes.c_int),
                ("columns", ctypes.c_int),
                ("names", _NAMES),
                ("table", _PD),
                ("start_parameter", ctypes.c_double),
                ("ended", ctypes.c_char_p),
                ("special_points", ctypes.c_int),
                ("special_lo", _PD),
                ("special_hi", _PD),
                ("special_kind", _NAMES),
                ("rhs_evaluations", ctypes.c_long),
                ("seconds", ctypes.c_double)]


class swim_member(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("completed", ctypes.c_int),
                ("status", ctypes.c_char * 32),
                ("reason", ctypes.c_char * 1024),
                ("t_reached", ctypes.c_double),
                ("x", ctypes.c_double),
                ("y", ctypes.c_double),
                ("theta", ctypes.c_double),
                ("energy_drift_rel", ctypes.c_double),
                ("energy_balance_abs", ctypes.c_double),
                ("jmin", ctypes.c_double),
                ("steps", ctypes.c_longlong),
                ("rhs_evaluations", ctypes.c_longlong),
                ("integrate_seconds", ctypes.c_double),
                ("wall_seconds", ctypes.c_double)]


class swim_optimize_options(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("vary", _NAMES),
                ("nvary", ctypes.c_int),
                ("quantity", ctypes.c_char_p),
                ("maximize", ctypes.c_int),
                ("method", ctypes.c_char_p),
                ("starts", ctypes.c_int),
                ("max_iter", ctypes.c_int),
                ("tol", ctypes.c_double),
                ("stop", ctypes.POINTER(ctypes.c_int))]


class swim_optimize_result(_Sized):
    _fields_ = [("size", ctypes.c_size_t),
                ("converged", ctypes.c_int),
                ("search_converged", ctypes.c_int),
                ("interrupted", ctypes.c_int),
                ("nkeys", ctypes.c_int),
                ("keys", _NAMES),
                ("best", _PD),
                ("value", ctypes.c_double),
                ("x", ctypes.c_double),
                ("y", ctypes.c_double),
                ("theta", ctypes.c_double),
                ("work", ctypes.c_double),
                ("forcing_work", ctypes.c_double),
                ("energy", ctypes.c_double),
                ("tight_status", ctypes.c_int),
                ("tight_value", ctypes.c_double),
                ("tight_change", ctypes.c_double),
                ("value_tolerance", ctypes.c_double),
                ("holds", ctypes.c_int),
                ("iterations", ctypes.c_int),
                ("evaluations", ctypes.c_long),
                ("gradient_evaluations", ctypes.c_long),
                ("failed_evaluations", ctypes.c_long),
                ("starts", ctypes.c_int),
                ("best_start", ctypes.c_int),
                ("seconds", ctypes.c_double)]


# The mirrors checked against the library at load, by swim.h's names.
MIRRORS = (swim_error, swim_sim_options, swim_result, swim_inspection, swim_event, swim_lyapunov_result,
           swim_orbit_options, swim_periodic_result, swim_floquet_result, swim_branch_result, swim_member,
           swim_optimize_options, swim_optimize_result)


def size_mismatches(lib, mirrors=None):
    """"NAME: N bytes here, M in the library" for each mirror (default MIRRORS) whose size is not
    the library's."""
    out = []
    mirrors = MIRRORS if mirrors is None else mirrors
    for m in mirrors:
        theirs = lib.swim_struct_size(m.__name__.encode())
        if theirs != ctypes.sizeof(m):
            out.append("%s: %d bytes here, %d in the library" % (m.__name__, ctypes.sizeof(m), theirs))
    return out


def _tree_libraries(tree):
    """`make lib`'s libraries in the source tree TREE: build/lib/libswim.so.VERSION first, then any
    other version left there, newest first (a VERSION edited since the build)."""
    out = []
    built = os.path.join(tree, "build", "lib")
    version_file = os.path.join(tree, "VERSION")
    if os.path.isfile(version_file):
        with open(version_file) as f:
            out.append(os.path.join(built, "libswim.so." + f.read().strip()))
    out += sorted(glob.glob(os.path.join(built, "libswim.so.*")), key=os.path.getmtime, reverse=True)
    return out


def candidates():
    """Where libswim may be, in the order tried: $SWIM_LIB; the installed layout (this package in
    PREFIX/lib/python3/dist-packages/swim, the library in PREFIX/lib); the build tree (this package
    in python/swim of the source tree); for a package installed by pip, the checkout it was built
    from (recorded in swim/_checkout.py), then the PREFIX of a `swim` on PATH and /usr/local, where
    `make install` puts libswim by default. There, the SONAME's symlink libswim.so.ABI: the ABI
    these prototypes were written against."""
    here = os.path.dirname(os.path.abspath(__file__))
    env = os.environ.get("SWIM_LIB")
    if env:
        return [env]   # asked for this one: no silent fallback to another build
    out = []
    if os.path.basename(os.path.dirname(here)) in ("dist-packages", "site-packages"):
        # PREFIX/lib/python3/dist-packages/swim -> PREFIX/lib/libswim.so.ABI
        out.append(os.path.normpath(os.path.join(here, "..", "..", "..", SONAME)))
    out += _tree_libraries(os.path.normpath(os.path.join(here, "..", "..")))
    try:
        from . import _checkout   # written by python/setup.py into a pip-built package only
        out += _tree_libraries(_checkout.TREE)
    except ImportError:
        pass
    program = shutil.which("swim")
    if program:
        prefix = os.path.dirname(os.path.dirname(os.path.realpath(program)))
        out.append(os.path.join(prefix, "lib", SONAME))
    out.append("/usr/local/lib/" + SONAME)
    return list(dict.fromkeys(out))


def _declare(lib):
    c_int, c_char_p, c_double, c_void_p = ctypes.c_int, ctypes.c_char_p, ctypes.c_double, ctypes.c_void_p
    err = ctypes.POINTER(swim_error)
    pp = ctypes.POINTER(c_void_p)
    sets = ctypes.POINTER(c_char_p)
    protos = {
        "swim_version": (c_char_p, []),
        "swim_strerror": (c_char_p, [c_int]),
        "swim_struct_size": (ctypes.c_size_t, [c_char_p]),
        "swim_model_set": (c_int, [c_void_p, c_char_p, c_char_p, err]),
        "swim_model_from_file": (c_int, [c_char_p, sets, c_int, pp, err]),
        "swim_model_from_text": (c_int, [c_char_p, c_char_p, sets, c_int, pp, err]),
        "swim_model_columns": (c_int, [c_void_p, ctypes.POINTER(sets)]),
        "swim_model_scene_text": (c_char_p, [c_void_p]),
        "swim_model_free": (None, [c_void_p]),
        "swim_sim_create": (c_int, [c_void_p, ctypes.POINTER(swim_sim_options), pp, err]),
        "swim_sim_advance": (c_int, [c_void_p, c_double, err]),
        "swim_sim_run": (c_int, [c_void_p, err]),
        "swim_sim_result": (c_int, [c_void_p, ctypes.POINTER(swim_result)]),
        "swim_sim_state": (c_int, [c_void_p, _PD, c_int]),
        # malloc'd text: kept as a raw pointer so that it can be given back to swim_free
        "swim_sim_summary_json": (c_void_p, [c_void_p]),
        "swim_sim_events_csv": (c_void_p, [c_void_p]),
        "swim_sim_free": (None, [c_void_p]),
        "swim_family_column": (c_char_p, [c_int, ctypes.POINTER(c_char_p)]),
        "swim_sim_state_at": (c_int, [c_void_p, c_double, _PD, c_int, err]),
        "swim_sim_sensitivity": (c_int, [c_void_p, ctypes.POINTER(sets), ctypes.POINTER(c_int), ctypes.POINTER(_PD),
                                         ctypes.POINTER(ctypes.c_long)]),
        "swim_sim_lyapunov": (c_int, [c_void_p, ctypes.POINTER(swim_lyapunov_result)]),
        "swim_inspect": (c_int, [c_int, _PD, _PD, c_double, c_double, ctypes.POINTER(swim_inspection), err]),
        "swim_free": (None, [c_void_p]),
        "swim_periodic_orbit": (c_int, [c_void_p, ctypes.POINTER(swim_orbit_options), pp, err]),
        "swim_floquet_multipliers": (c_int, [c_void_p, ctypes.POINTER(swim_orbit_options), pp, err]),
        "swim_continuation": (c_int, [c_void_p, ctypes.POINTER(swim_orbit_options), pp, err]),
        "swim_orbit_periodic": (c_int, [c_void_p, ctypes.POINTER(swim_periodic_result)]),
        "swim_orbit_floquet": (c_int, [c_void_p, ctypes.POINTER(swim_floquet_result)]),
        "swim_orbit_branch": (c_int, [c_void_p, ctypes.POINTER(swim_branch_result)]),
        "swim_optimize": (c_int, [c_void_p, ctypes.POINTER(swim_optimize_options), pp, err]),
        "swim_orbit_optimize": (c_int, [c_void_p, ctypes.POINTER(swim_optimize_result)]),
        "swim_orbit_json": (c_void_p, [c_void_p]),
        "swim_orbit_csv": (c_void_p, [c_void_p]),
        "swim_orbit_free": (None, [c_void_p]),
        "swim_model_run_member": (c_int, [c_void_p, sets, c_int, sets, c_int, ctypes.POINTER(swim_member), err]),
    }
    for name, (restype, argtypes) in protos.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = restype, argtypes
    return lib


def load():
    """The loaded library, or (None, a message saying what was tried and how to build it)."""
    tried = []
    for path in candidates():
        if not os.path.exists(path):
            tried.append(path + " (absent)")
            continue
        try:
            lib = _declare(ctypes.CDLL(path))
        except OSError as e:
            tried.append("%s (%s)" % (path, e))
        except AttributeError as e:   # a library of another version, without a function of swim.h
            tried.append("%s (%s)" % (path, e))
            continue
        wrong = size_mismatches(lib)
        if not wrong:
            return lib, None
        tried.append("%s (its structs are not this package's: %s)" % (path, "; ".join(wrong)))
    return None, ("libswim not found; tried: " + "; ".join(tried) +
                  ". Build it with `make lib` in the source tree, install it with `make install PREFIX=...` "
                  "(then put PREFIX/bin on PATH), or set SWIM_LIB to the path of libswim.so")
