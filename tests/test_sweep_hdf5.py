"""swim sweep --format hdf5: the family in one DIR/family.h5 that h5py reads -- the definition
(sweep.json's text), the scene, the members table equal to members.csv value for value (numbers to
the last bit, in id order), and with --keep trajectories every member's trajectory equal to its
trajectory.csv; a failed member is a row like in members.csv; CSV stays the default (no family.h5
without --format hdf5) and an unknown format is refused in one line before any work."""

import csv
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import swimtest  # noqa: E402
from swimtest import TMP, check, swim  # noqa: E402

EX3 = "models/example3.toml"


def members_csv(folder):
    with open(os.path.join(folder, "members.csv")) as fh:
        return list(csv.DictReader(fh))


def test_family_file():
    out = os.path.join(TMP, "family")
    p = swim("sweep", EX3, "--out", out, "--vary", "model.rho0=1,2.5", "--vary", "run.t_end=0.3,0.6",
             "--keep", "trajectories", "--format", "hdf5", "--jobs", "2", "--quiet")
    check(p.returncode == 0, "the sweep ran: %s" % p.stderr[-300:])
    rows = members_csv(out)
    with h5py.File(os.path.join(out, "family.h5"), "r") as f:
        with open(os.path.join(out, "sweep.json")) as fh:
            check(f.attrs["definition"] == fh.read(), "the definition is sweep.json's text")
        with open(os.path.join(out, "scene.toml")) as fh:
            check(f.attrs["scene"] == fh.read(), "the scene is the text the members ran")
        check(int(f.attrs["members"]) == 4, "four members")
        with open("VERSION") as fh:
            check(f.attrs["swim_version"] == fh.read().strip(), "swim's version")
        g = f["members"]
        order = [c for c in g.attrs["columns"]]
        check(all(isinstance(c, str) for c in order) and all(isinstance(f.attrs[k], str) for k in
              ("definition", "scene", "swim_version")), "the text attributes come back from h5py as str")
        check(order == list(rows[0].keys()), "the columns in members.csv's order: %s" % order)
        check(list(g["id"][:]) == [int(r["id"]) for r in rows] == [0, 1, 2, 3], "ids in order")
        for name in order:
            col = g[name]
            if name in ("status", "reason"):
                # UTF-8 variable-length strings: h5py reads a string dataset as bytes whatever its
                # encoding (its documented rule), .asstr() as str; attributes come back as str
                info = h5py.check_string_dtype(col.dtype)
                check(info is not None and info.encoding == "utf-8" and info.length is None,
                      "%s: variable-length UTF-8 strings (%r)" % (name, info))
                got = [s for s in col.asstr()[:]]
                want = [r[name] for r in rows]
                check(got == want, "%s as in members.csv" % name)
            elif name in ("steps", "rhs_evaluations", "id"):
                check([int(v) for v in col[:]] == [int(r[name]) for r in rows], "%s as in members.csv" % name)
            else:
                want = np.array([float(r[name]) if r[name] != "" else np.nan for r in rows])
                check(np.array_equal(col[:], want, equal_nan=True), "%s to the last bit" % name)
        for r in rows:
            name = "%05d" % int(r["id"])
            path = os.path.join(out, "members", name, "trajectory.csv")
            want = np.atleast_2d(np.loadtxt(path, delimiter=",", skiprows=1))
            with open(path) as fh:
                header = fh.readline().strip().split(",")
            ds = f["trajectories"][name]
            check(np.array_equal(ds[:], want) and list(ds.attrs["columns"]) == header,
                  "member %s: trajectory.csv in the file, bit for bit, with its columns" % name)


def test_csv_default_and_bad_format():
    out = os.path.join(TMP, "csv")
    p = swim("sweep", EX3, "--out", out, "--vary", "model.rho0=1,2", "--t-end", "0.2", "--quiet")
    check(p.returncode == 0 and not os.path.exists(os.path.join(out, "family.h5")),
          "no family.h5 without --format hdf5")
    bad = os.path.join(TMP, "bad")
    p = swim("sweep", EX3, "--out", bad, "--vary", "model.rho0=1,2", "--format", "netcdf")
    check(p.returncode == 2 and swimtest.one_line(p) and "--format" in p.stderr and not os.path.exists(bad),
          "--format netcdf: one line, exit 2, nothing made: %r" % p.stderr)


def test_failed_member_row():
    out = os.path.join(TMP, "failing")
    # Example 1 with gamma = 0.8: the shape leaves D during the run (as in test_sweep)
    p = swim("sweep", "models/example1.toml", "--out", out, "--t-end", "5", "--vary", "shape.c0.am1=0.5,0.8",
             "--format", "hdf5", "--keep", "trajectories", "--quiet")
    rows = members_csv(out)
    with h5py.File(os.path.join(out, "family.h5"), "r") as f:
        status = list(f["members/status"].asstr()[:])
        failed_rows = f["trajectories/00001"].shape[0]
    check(p.returncode == 1 and status == [r["status"] for r in rows] == ["completed", "failed"],
          "a failed member is a row of the file as of members.csv: %s (%s)" % (status, p.stderr[-200:]))
    check(failed_rows > 1, "the failed member's rows up to its failure are kept (%d)" % failed_rows)


sys.exit(swimtest.main(globals(), "test_sweep_hdf5"))
