"""Refine every mesh under a directory on a Dask cluster, one task per file.

Usage::

    python examples/python/dask_batch.py IN_DIR OUT_DIR [--scheme S] --levels N \\
        [--format obj|ply|glb|usda|usdc|usdz] [--workers W] [--threads-per-worker T] \\
        [--scheduler ADDRESS] [--verbose]

    # 4 local worker processes, Catmull-Clark twice:
    python examples/python/dask_batch.py scans/ refined/ --scheme catmull-clark \\
        --levels 2 --workers 4

    # a running cluster (`dask scheduler`, then `dask worker tcp://host:8786` on each node):
    python examples/python/dask_batch.py /shared/scans /shared/refined --scheme loop \\
        --levels 3 --scheduler tcp://host:8786

Inputs are the files under IN_DIR, searched recursively, whose extension subd reads
(.obj, .ply, .gltf, .glb, .usd, .usda, .usdc, .usdz, in any case), in sorted order; files
under OUT_DIR are left out when OUT_DIR lies inside IN_DIR. Each input gives
``OUT_DIR/<stem>.<ext>``: ``ext`` is the input's own (a .gltf input gives .glb, which subd
writes) unless ``--format`` names one. A USD stage with several mesh prims gives one task
per prim, named after the stem and the prim's path (``scene.usda``'s ``/World/Body``:
``scene_World_Body.usda``), as the CLI's batch mode (``--out-dir``) names them. Without
``--scheme`` each mesh is refined with the scheme its file names (USD's
``subdivisionScheme``), else Catmull-Clark.

Outputs are named by stem alone, so two inputs that would write the same output (``a/x.obj``
and ``b/x.obj``; compared ignoring case, since a case-insensitive file system would
overwrite one with the other) are refused before anything runs, with exit status 2 and
every clash named, as is OUT_DIR = IN_DIR. Rename the inputs or run the subfolders
separately.

Each task runs on a worker: it reads the file, refines it and writes the output. subd
writes atomically (a temporary file beside the output, renamed when complete), so a file
that fails leaves no output, whole or partial. A failure is printed on stderr as one line,
``subd: <path>: <message>`` (a parse error's message already starts with the path and
line, which are not repeated: ``subd: <path>:<line>: <message>``), and the other files go
on. ``--verbose`` adds a line on stdout per file refined. At the end one line on stdout
sums up: ``N refined, K failed, F faces out, S s`` (wall time, cluster start included).

Exit status: 0 when every file was refined, 1 when some failed (the others were refined
and written), 2 for bad arguments or when nothing could be run: an unknown option, IN_DIR
not a directory or holding no mesh, clashing outputs, OUT_DIR not creatable, a scheduler
that cannot be reached.

Threads: a subd call spreads its work over its own pool of threads, one per core unless
told otherwise. W worker processes on one machine, each with such a pool, would run
W x cores threads on the cores, oversubscribing them. Files are independent, so
parallelism across files is enough when there are more files than workers: each worker
process therefore gets a pool of ``--threads-per-worker`` threads (default 1), set by a
worker plugin (:class:`SubdThreads`), which also reaches workers that join later and stays
registered with the cluster. Raise it when there are fewer, larger meshes than cores (W=2,
T=8 on 16 cores, say), or give 0 (one per core) with one worker process per machine. subd's
results do not depend on the thread count.

Without ``--scheduler`` the cluster is a ``LocalCluster`` of W worker processes (default:
one per CPU, at most one per file), each running one task at a time. With ``--scheduler``
the cluster's workers are used as they are: a worker started with ``--nthreads k`` runs k
tasks at once, each on T subd threads, so pick k x T near the cores it has. IN_DIR and
OUT_DIR must then be on a file system every worker sees at the same path (they are made
absolute, symbolic links resolved, where this script runs).

The functions can be used from other code with any ``distributed.Client`` (a
``dask_jobqueue.SLURMCluster``'s, say): :func:`plan` then :func:`refine_all`. Workers that
do not share this machine's ``sys.path`` need the module: ``client.upload_file(path)``.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import time
from pathlib import Path
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import subd
from distributed import Client, LocalCluster, WorkerPlugin, as_completed

INPUT_EXTENSIONS = (".obj", ".ply", ".gltf", ".glb", ".usd", ".usda", ".usdc", ".usdz")
"""Extensions of the files taken as inputs (compared ignoring case)."""

OUTPUT_FORMATS = ("obj", "ply", "glb", "usda", "usdc", "usdz")
"""Formats subd writes."""

EXIT_OK = 0
EXIT_SOME_FAILED = 1
EXIT_BAD_ARGUMENTS = 2

Job = Tuple[str, str, Optional[str]]
"""An (input path, output path, mesh prim) triple, both paths absolute; the prim is the USD
mesh prim to read, None for the file's only mesh."""

Record = Dict[str, object]
"""A task's outcome: ``input``, ``output``, ``prim``, ``faces_in``, ``faces_out``, ``seconds``,
``error`` (the message, None on success) and ``error_type`` (the exception's class name)."""


class PlanError(ValueError):
    """The inputs cannot be mapped to outputs (no inputs, clashing or overwriting outputs)."""


def find_meshes(in_dir: Path, exclude: Optional[Path] = None) -> List[Path]:
    """The files under ``in_dir`` (recursively) whose extension subd reads, sorted; none
    under ``exclude``. Symbolic links to directories are not followed."""
    found = []
    for root, dirs, files in os.walk(in_dir):
        if exclude is not None:
            dirs[:] = [d for d in dirs if Path(root, d) != exclude]
        found += [Path(root, f) for f in files if f.lower().endswith(INPUT_EXTENSIONS)]
    return sorted(found)


def output_path(src: Path, out_dir: Path, fmt: Optional[str] = None,
                prim: Optional[str] = None) -> Path:
    """``out_dir/<name>.<ext>``: ``name`` is the stem, followed by the parts of ``prim``'s
    path where there is one; ``ext`` is ``fmt``, else the input's (.gltf gives .glb)."""
    ext = fmt or src.suffix.lower().lstrip(".")
    if ext == "gltf":
        ext = "glb"
    name = "_".join([src.stem] + [part for part in (prim or "").split("/") if part])
    return out_dir / f"{name}.{ext}"


def prims_of(src: Path) -> List[Optional[str]]:
    """The items of one input: each mesh prim of a USD stage with several, else the file
    (None). A stage that cannot be opened is one item, which fails when its task runs."""
    if not src.suffix.lower().startswith(".usd"):
        return [None]
    try:
        prims = [p["path"] for p in subd.mesh_prims(src)]
    except (subd.SubdError, ValueError, OSError):
        return [None]
    return prims if len(prims) > 1 else [None]


def plan(in_dir, out_dir, fmt: Optional[str] = None) -> List[Job]:
    """The jobs refining every mesh under ``in_dir`` into ``out_dir`` (see the module's
    docstring for the naming), as absolute paths with symbolic links resolved.

    Raises :class:`PlanError` when ``out_dir`` is ``in_dir``, when there is no input and
    when two inputs would write the same output (compared ignoring case).
    """
    in_dir, out_dir = Path(in_dir).resolve(), Path(out_dir).resolve()
    if out_dir == in_dir:
        raise PlanError(f"{out_dir}: OUT_DIR is IN_DIR: the outputs would overwrite the inputs")
    inputs = find_meshes(in_dir, exclude=out_dir)
    if not inputs:
        raise PlanError(f"{in_dir}: no {', '.join(INPUT_EXTENSIONS)} files under it")
    jobs, first, clashes = [], {}, []
    for src in inputs:
        for prim in prims_of(src):
            dst = output_path(src, out_dir, fmt, prim)
            key = str(dst).casefold()
            item = src if prim is None else f"{src} {prim}"
            if key in first:
                clashes.append(f"{dst}: {first[key]} and {item} would both write it")
            else:
                first[key] = item
            jobs.append((str(src), str(dst), prim))
    if clashes:
        raise PlanError("; ".join(clashes) + " (outputs are named after the input's stem)")
    return jobs


class SubdThreads(WorkerPlugin):
    """Sets the size of subd's thread pool in every worker process (0: one per core)."""

    name = "subd-threads"

    def __init__(self, threads: int) -> None:
        self.threads = threads

    def setup(self, worker) -> None:
        subd.set_num_threads(self.threads)


def refine_one(src: str, dst: str, scheme: Optional[str], levels: int,
               prim: Optional[str] = None) -> Record:
    """Reads ``src`` (its mesh prim ``prim``, for a USD stage with several), refines it
    with ``scheme`` (None: the one the file names, else Catmull-Clark) and writes ``dst``
    (creating its directory): the task each worker runs.

    subd's own errors (a file that does not parse, a mesh the scheme refuses), any other
    ``ValueError`` and ``OSError`` (unreadable input, unwritable output) are returned in
    the record; anything else is a bug and propagates, with its traceback, to the client.
    """
    start = time.perf_counter()
    record: Record = {"input": src, "output": dst, "prim": prim, "faces_in": None,
                      "faces_out": None, "seconds": None, "error": None, "error_type": None}
    try:
        mesh = subd.read(src, prim=prim)
        record["faces_in"] = mesh.num_faces
        fine = subd.refine(mesh, scheme, levels)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        fine.write(dst)
        record["faces_out"] = fine.num_faces
    except (subd.SubdError, ValueError, OSError) as e:
        record["error"], record["error_type"] = str(e), type(e).__name__
    record["seconds"] = time.perf_counter() - start
    return record


def failed_record(job: Job, error: BaseException) -> Record:
    """The record of a task that did not return one (it raised, or its worker died)."""
    return {"input": job[0], "output": job[1], "prim": job[2], "faces_in": None,
            "faces_out": None,
            "seconds": None, "error": str(error) or repr(error),
            "error_type": type(error).__name__}


def refine_all(
    client,
    jobs: Sequence[Job],
    scheme: Optional[str],
    levels: int,
    threads: int = 1,
    report: Optional[Callable[[Record], None]] = None,
) -> List[Record]:
    """Refines every job on ``client``'s cluster, one task per file (``client.map``).

    ``threads`` is the size of subd's pool in each worker process (0: one per core),
    registered as a worker plugin: it stays with the cluster after the call. ``report`` is
    called on this machine with each record as its task completes (in completion order);
    the records are returned in the order of ``jobs``. A task that raises or loses its
    worker gives a failed record: the batch always finishes.
    """
    client.register_plugin(SubdThreads(threads))
    srcs, dsts, prims = [j[0] for j in jobs], [j[1] for j in jobs], [j[2] for j in jobs]
    # pure=False: the tasks write files, so two equal calls are not one.
    # Keywords would be given whole to every task: the per-job prims go by position.
    n = len(jobs)
    futures = client.map(refine_one, srcs, dsts, [scheme] * n, [levels] * n, prims, pure=False)
    index = {f.key: i for i, f in enumerate(futures)}
    records: List[Optional[Record]] = [None] * len(futures)
    for future in as_completed(futures):
        i = index[future.key]
        try:
            record = future.result()
        except Exception as e:  # a bug in the task, or a worker that died (KilledWorker)
            record = failed_record(jobs[i], e)
        records[i] = record
        future.release()
        if report is not None:
            report(record)
    return records  # type: ignore[return-value]


def error_line(record: Record) -> str:
    """``subd: <path>: <message>`` on one line (``<path> <prim>`` for a prim of a stage with
    several); a message that starts with the path (a parse error's ``<path>:<line>: ...``)
    is not prefixed with it again."""
    src, message = str(record["input"]), " ".join(str(record["error"]).split())
    if record.get("prim"):
        return f"subd: {src} {record['prim']}: {message}"
    if message.startswith(src + ":"):
        return f"subd: {message}"
    return f"subd: {src}: {message}"


def summary_line(records: Sequence[Record], seconds: float) -> str:
    """``N refined, K failed, F faces out, S s``."""
    ok = [r for r in records if r["error"] is None]
    faces = sum(int(r["faces_out"]) for r in ok)  # type: ignore[arg-type]
    return f"{len(ok)} refined, {len(records) - len(ok)} failed, {faces} faces out, {seconds:.2f} s"


@contextlib.contextmanager
def open_client(scheduler: Optional[str], workers: int):
    """A client of the scheduler at ``scheduler``, else of a new ``LocalCluster`` of
    ``workers`` processes, each running one task at a time (the parallelism within a task
    is subd's); closed, with the local cluster, on leaving."""
    if scheduler:
        with Client(scheduler) as client:
            yield client
    else:
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            yield client


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    """The command line; exits with status 2 on a bad one (argparse's convention)."""
    p = argparse.ArgumentParser(
        description="Refine every mesh under IN_DIR into OUT_DIR on a Dask cluster.",
        epilog="Exit status: 0 all refined, 1 some failed, 2 bad arguments.",
    )
    p.add_argument("in_dir", metavar="IN_DIR", type=Path)
    p.add_argument("out_dir", metavar="OUT_DIR", type=Path, help="created if missing")
    p.add_argument("--scheme", choices=subd.SCHEMES,
                   help="default: the scheme each file names (USD), else catmull-clark")
    p.add_argument("--levels", required=True, type=int)
    p.add_argument("--format", choices=OUTPUT_FORMATS,
                   help="output format (default: the input's; .gltf gives .glb)")
    p.add_argument("--workers", type=int, metavar="W",
                   help="local worker processes (default: one per CPU, at most one per file)")
    p.add_argument("--threads-per-worker", type=int, default=1, metavar="T",
                   help="subd threads in each worker process (default 1; 0: one per core)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="a running scheduler, e.g. tcp://host:8786, instead of a local cluster")
    p.add_argument("-v", "--verbose", action="store_true",
                   help="one line per refined file on stdout")
    args = p.parse_args(argv)
    if args.levels < 0:
        p.error("--levels: must be 0 or more")
    if args.workers is not None and args.workers < 1:
        p.error("--workers: must be 1 or more")
    if args.threads_per_worker < 0:
        p.error("--threads-per-worker: must be 0 or more")
    if args.scheduler and args.workers is not None:
        p.error("--workers: the cluster at --scheduler has its own workers")
    if not args.in_dir.is_dir():
        p.error(f"{args.in_dir}: not a directory")
    return args


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Runs the command line; returns the exit status."""
    start = time.perf_counter()
    args = parse_args(argv)
    try:
        jobs = plan(args.in_dir, args.out_dir, args.format)
        args.out_dir.mkdir(parents=True, exist_ok=True)
    except (PlanError, OSError) as e:
        print(f"subd: {e}", file=sys.stderr)
        return EXIT_BAD_ARGUMENTS

    def report(record: Record) -> None:
        if record["error"] is not None:
            print(error_line(record), file=sys.stderr, flush=True)
        elif args.verbose:
            print(f"{record['input']} -> {record['output']}: {record['faces_in']} -> "
                  f"{record['faces_out']} faces, {record['seconds']:.3f} s", flush=True)

    workers = min(args.workers or os.cpu_count() or 1, len(jobs))
    with contextlib.ExitStack() as stack:
        try:
            client = stack.enter_context(open_client(args.scheduler, workers))
        except OSError as e:  # TimeoutError included
            print(f"subd: {args.scheduler or 'local cluster'}: cannot connect: {e}",
                  file=sys.stderr)
            return EXIT_BAD_ARGUMENTS
        records = refine_all(client, jobs, args.scheme, args.levels,
                             threads=args.threads_per_worker, report=report)
    print(summary_line(records, time.perf_counter() - start), flush=True)
    return EXIT_OK if all(r["error"] is None for r in records) else EXIT_SOME_FAILED


if __name__ == "__main__":
    sys.exit(main())
