"""How long does grading take on a Dask scheduler compared with the local pool?

Workload: COUNT copies of the reference solutions, graded with the course's full
checks (hidden ones included) by ``msdlab grade`` twice: ``--jobs WORKERS`` and
``--cluster ADDRESS`` of a Dask `LocalCluster` of WORKERS single-threaded worker
processes, started before the run. Prints the wall time of each run and the mean
seconds per submission; both runs must write the same CSV.

    python benchmarks/grading_cluster.py               # 6 submissions, 2 workers
    python benchmarks/grading_cluster.py --count 100 --workers 2 --cluster-first
"""

from __future__ import annotations

import argparse
import contextlib
import io
import shutil
import tempfile
import time
from pathlib import Path

from dask.distributed import LocalCluster

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT


def run(count: int, workers: int, cluster_first: bool) -> None:
    with tempfile.TemporaryDirectory(prefix="msdlab-bench-") as folder:
        root = Path(folder)
        submissions = []
        for i in range(count):
            shutil.copytree(PROJECT_ROOT / "solutions", root / f"student{i:04d}")
            submissions.append(str(root / f"student{i:04d}"))
        tables = {}
        options = dict(threads_per_worker=1, dashboard_address=None, memory_limit=0)
        with LocalCluster(n_workers=workers, **options) as cluster:
            runs = [
                (f"--jobs {workers}", ["--jobs", str(workers)]),
                ("--cluster ADDRESS", ["--cluster", cluster.scheduler_address]),
            ]
            for label, where in reversed(runs) if cluster_first else runs:
                out = root / "grades.csv"
                started = time.perf_counter()
                with (
                    contextlib.redirect_stdout(io.StringIO()),
                    contextlib.redirect_stderr(io.StringIO()),
                ):
                    status = main(["grade", *submissions, "--out", str(out), *where])
                seconds = time.perf_counter() - started
                tables[label] = out.read_text()
                print(f"{label:<20} {count} submissions in {seconds:6.1f} s, "
                      f"{seconds / count:5.2f} s each, exit {status}")  # fmt: skip
        assert len(set(tables.values())) == 1, "the two runs wrote different CSVs"


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=6, help="submissions (%(default)s)")
    parser.add_argument("--workers", type=int, default=2, help="processes (%(default)s)")
    parser.add_argument(
        "--cluster-first", action="store_true", help="run the cluster first (the load may change)"
    )
    arguments = parser.parse_args()
    run(arguments.count, arguments.workers, arguments.cluster_first)
