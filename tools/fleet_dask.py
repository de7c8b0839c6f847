#!/usr/bin/env python3
"""eha fleet on a Dask distributed cluster.

Maps ``eha diagnose LOG --json FILE`` over a fleet's bench logs on the workers of a
``dask.distributed`` cluster and gathers the diagnoses into the output folder, as the
records ``eha fleet`` keeps (``DIR/diagnoses/<sha256>.json``); then ``eha fleet`` itself,
with every diagnosis already kept, writes the very tables it would have written alone
(``fleet.csv``, ``fleet.json``, ``trends.csv``, ``plots/``):

    python3 tools/fleet_dask.py PATH... --out DIR [--manifest CSV] [--rig RIG]
        [--eha EHA] (--scheduler ADDRESS | --local-workers N) [--timeout S]

The logs, their order and their hashes come from ``eha fleet --plan`` (one source of
truth, so the table cannot differ); a log whose diagnosis is already kept in DIR is not
sent again. Workers run ``eha`` on the paths they are given: on a cluster, the logs and
the eha executable must be on a file system every worker sees (as on the usual HPC
shared home or scratch). ``--scheduler`` connects to a running cluster (``dask
scheduler`` and ``dask worker``, or ``dask-jobqueue``'s ``SLURMCluster``, ``PBSCluster``,
``LSFCluster``, see docs/fleet.md); ``--local-workers N`` starts a local cluster of N
single-threaded worker processes. Exit status: eha fleet's (0 all diagnosed, 1 some
failed, 2 bad arguments).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

from dask.distributed import Client, LocalCluster, as_completed


def diagnose(eha, rig, path, sha256, timeout):
    """One log on a worker: ``eha [--rig RIG] diagnose PATH --json FILE``.

    Returns ``(sha256, outcome, payload)``: ``("ok", diagnosis)`` on exit status 0,
    ``("bad_input", message)`` on 2 (the log's content decides both: kept), and
    ``("failed", message)`` otherwise (killed, timed out: not kept, eha fleet tries again).
    """
    fd, out = tempfile.mkstemp(suffix=".json", prefix="eha-fleet-")
    os.close(fd)
    try:
        cmd = [eha] + (["--rig", rig] if rig else []) + ["diagnose", path, "--json", out]
        try:
            done = subprocess.run(
                cmd,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                timeout=timeout,
            )
        except subprocess.TimeoutExpired:
            return sha256, "failed", f"diagnosis of `{path}` stopped after {timeout} s"
        lines = [l.strip() for l in done.stderr.decode("utf-8", "replace").splitlines()]
        lines = [l for l in lines if l]
        errors = [l[len("eha: error: "):] for l in lines if l.startswith("eha: error: ")]
        message = errors[-1] if errors else (lines[-1] if lines else "")
        if done.returncode == 0:
            with open(out, encoding="utf-8") as f:
                return sha256, "ok", json.load(f)
        if done.returncode == 2:
            return sha256, "bad_input", message or f"bench log `{path}`: refused as bad input"
        if done.returncode < 0:
            return sha256, "failed", f"diagnosis of `{path}` killed by signal {-done.returncode}"
        return sha256, "failed", f"diagnosis failed (exit status {done.returncode}): {message}"
    finally:
        if os.path.exists(out):
            os.remove(out)


def keep(record_path, sha256, plan, outcome, payload):
    """Writes the record eha fleet reads back, atomically (temporary file, rename)."""
    record = {
        "sha256": sha256,
        "rig_sha256": plan["rig_sha256"],
        "eha_version": plan["eha_version"],
        "outcome": outcome,
    }
    record["diagnosis" if outcome == "ok" else "error"] = payload
    folder = os.path.dirname(record_path)
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".dask-", suffix=".json")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(record, f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, record_path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def fleet_args(a):
    """The arguments of eha fleet that choose the logs and the rig."""
    args = list(a.paths) + ["--out", a.out]
    if a.manifest:
        args += ["--manifest", a.manifest]
    if a.shard:
        args += ["--shard", a.shard]
    rig = ["--rig", a.rig] if a.rig else []
    return rig, args


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("paths", nargs="*", metavar="PATH", help="bench logs or folders")
    p.add_argument("--out", required=True, metavar="DIR")
    p.add_argument("--manifest", metavar="CSV")
    p.add_argument("--shard", metavar="K/N")
    p.add_argument("--rig", metavar="RIG", help="rig file (eha --rig)")
    p.add_argument("--eha", default="eha", metavar="EHA", help="the eha executable")
    p.add_argument("--json", metavar="PATH", help="eha fleet's summary (--json)")
    p.add_argument("--timeout", type=float, metavar="S", help="longest one diagnosis may take")
    where = p.add_mutually_exclusive_group(required=True)
    where.add_argument("--scheduler", metavar="ADDRESS", help="a running cluster's scheduler")
    where.add_argument("--local-workers", type=int, metavar="N", help="a local cluster of N workers")
    a = p.parse_args()

    eha = os.path.abspath(a.eha) if os.sep in a.eha else a.eha
    rig, args = fleet_args(a)
    planned = subprocess.run([eha] + rig + ["fleet"] + args + ["--plan", "-"], stdout=subprocess.PIPE)
    if planned.returncode != 0:
        return planned.returncode
    plan = json.loads(planned.stdout)
    todo = {}
    for log in plan["logs"]:
        if "sha256" in log and not log["kept"]:
            todo.setdefault(log["sha256"], log)

    if a.scheduler:
        client = Client(a.scheduler)
    else:
        cluster = LocalCluster(n_workers=a.local_workers, threads_per_worker=1, processes=True)
        client = Client(cluster)
    try:
        rig_path = os.path.abspath(a.rig) if a.rig else None
        futures = [
            client.submit(diagnose, eha, rig_path, os.path.abspath(log["path"]), sha, a.timeout,
                          key=f"diagnose-{sha}", pure=False)
            for sha, log in todo.items()
        ]
        failed = 0
        for future in as_completed(futures):
            sha, outcome, payload = future.result()
            if outcome == "failed":
                failed += 1
                print(f"fleet_dask: {payload}", file=sys.stderr)
                continue
            keep(todo[sha]["record"], sha, plan, outcome, payload)
        print(f"fleet_dask: {len(todo)} logs diagnosed on the cluster, {failed} failed "
              f"(eha fleet tries those again)", file=sys.stderr)
    finally:
        client.close()
        if not a.scheduler:
            cluster.close()

    # Every diagnosis is kept: eha fleet only reads them back and writes the tables.
    final = [eha] + rig + ["fleet"] + args + (["--json", a.json] if a.json else [])
    return subprocess.run(final).returncode


if __name__ == "__main__":
    sys.exit(main())
