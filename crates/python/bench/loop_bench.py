#!/usr/bin/env python3
"""Loop level 3 with subd against trimesh, libigl and PyMeshLab (issue 41, item 7).

Inputs:
  * ``torus``: a closed triangulated torus made here (``--grid`` squared quads, two
    triangles each: 224 gives 100,352 triangles, every vertex of valence 6);
  * ``scan``: the mesh of ``--scan PATH`` as ``subd.read(path,
    accept_inconsistent_orientation=True)`` gives it;
  * ``scan-manifold``: the same scan less the faces that make an edge non-manifold (see
    ``drop_for_manifold``), so that the tools that need an edge-manifold mesh can run.

Every (tool, mesh) pair runs in its own subprocess (``--worker TOOL MESH``), so the peak
memory (``ru_maxrss``) is the tool's own; the baseline is the peak after the imports and
the input arrays. The timed region is: the tool's conversion of the float64 ``(n, 3)`` and
int64 ``(m, 3)`` arrays, Loop level 3 (or Catmull-Clark level 3), and the result back as
numpy vertices and faces. Outputs are compared with subd's of the same scheme by nearest
vertex (``scipy.spatial.cKDTree``) and, where every vertex matches, by face sets.

    python loop_bench.py --scan target/xtask/bench/StanfordBunny.ply [--repeats 3] [--json out.json]
"""

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

LEVELS = 3
SLOW_S = 10.0  # a run longer than this is not repeated
AGREE = 1e-9
# (tool, scheme, subd threads: 0 = one per core, None = the library's own default)
RUNS = [
    ("subd", "loop", 1),
    ("subd", "loop", 0),
    ("igl", "loop", None),
    ("trimesh", "loop", None),
    ("pymeshlab", "loop", None),
    ("subd", "catmull-clark", 1),
    ("subd", "catmull-clark", 0),
    ("pymeshlab", "catmull-clark", None),
]
DISTRIBUTIONS = {"subd": "subd", "igl": "libigl", "trimesh": "trimesh", "pymeshlab": "pymeshlab"}


# --------------------------------------------------------------------------- inputs


def torus(n, r_major=1.0, r_minor=0.35):
    """A closed torus of ``n`` x ``n`` quads split into ``2 n^2`` triangles (valence 6)."""
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    u, w = 2 * np.pi * i / n, 2 * np.pi * j / n
    ring = r_major + r_minor * np.cos(w)
    v = np.stack([ring * np.cos(u), ring * np.sin(u), r_minor * np.sin(w)], -1).reshape(-1, 3)
    a, b = i * n + j, (i + 1) % n * n + j
    c, d = (i + 1) % n * n + (j + 1) % n, i * n + (j + 1) % n
    f = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return np.ascontiguousarray(v, np.float64), np.ascontiguousarray(f, np.int64)


def edge_table(f):
    """Directed edges of triangles ``f``: (edges (3m, 2), face of each, undirected id, faces per id)."""
    d = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    face = np.tile(np.arange(len(f)), 3)
    _, uid, count = np.unique(np.sort(d, axis=1), axis=0, return_inverse=True, return_counts=True)
    return d, face, uid.reshape(-1), count


def non_manifold_faces(f):
    """For each edge with more than two faces: (faces along the majority direction, the others)."""
    d, face, uid, count = edge_table(f)
    forward = d[:, 0] < d[:, 1]
    nm = np.flatnonzero(count[uid] > 2)
    nm = nm[np.argsort(uid[nm], kind="stable")]
    groups = np.split(nm, np.flatnonzero(np.diff(uid[nm])) + 1) if len(nm) else []
    out = []
    for g in groups:
        major = forward[g].sum() * 2 > len(g)
        out.append((face[g][forward[g] == major], face[g][forward[g] != major]))
    return out


def drop_for_manifold(f):
    """``f`` less, at every non-manifold edge, the last face of the majority direction."""
    drop = [major.max() for major, _ in non_manifold_faces(f)]
    return np.ascontiguousarray(np.delete(f, np.unique(drop), axis=0))


def describe(v, f):
    """Counts of a triangle mesh: vertices, faces, boundary and non-manifold edges, ..."""
    d, _, _, count = edge_table(f)
    _, directed = np.unique(d, axis=0, return_counts=True)
    used = np.unique(f).size
    return {
        "vertices": len(v), "faces": len(f), "edges": len(count),
        "boundary_edges": int((count == 1).sum()), "non_manifold_edges": int((count > 2).sum()),
        "repeated_directed_edges": int((directed > 1).sum()), "unused_vertices": len(v) - used,
        "closed": bool((count == 2).all()),
    }


def prepare_inputs(args, workdir):
    """Writes every input mesh as ``NAME_v.npy`` / ``NAME_f.npy``; returns {name: description}."""
    meshes = {"torus": torus(args.grid)}
    if args.scan:
        import subd

        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            scan = subd.read(args.scan, accept_inconsistent_orientation=True)
        v, f = np.ascontiguousarray(scan.vertices), scan.faces.astype(np.int64)
        meshes["scan"] = (v, f)
        meshes["scan-manifold"] = (v, drop_for_manifold(f))
    info = {}
    for name, (v, f) in meshes.items():
        np.save(os.path.join(workdir, f"{name}_v.npy"), v)
        np.save(os.path.join(workdir, f"{name}_f.npy"), f)
        info[name] = describe(v, f)
    if args.scan:
        info["scan"]["source"] = os.path.abspath(args.scan)
        info["scan"]["read_warnings"] = len(caught)
        info["scan-manifold"]["dropped_faces"] = info["scan"]["faces"] - info["scan-manifold"]["faces"]
    return info


# --------------------------------------------------------------------------- worker


def load_tool(tool, scheme, threads):
    """Imports ``tool``; returns (run(v, f) -> (vertices, faces), threads used or None)."""
    if tool == "subd":
        import subd

        if threads is not None:
            subd.set_num_threads(threads)

        def run(v, f):
            # The scan has edges two faces use in the same direction: taken, as read takes them.
            mesh = subd.Mesh(v, f, accept_inconsistent_orientation=True)
            out = subd.refine(mesh, scheme, levels=LEVELS)
            return out.vertices, out.faces

        return run, subd.get_num_threads()
    if tool == "igl":
        import igl

        return (lambda v, f: igl.loop(v, f, LEVELS)), None
    if tool == "trimesh":
        import trimesh.remesh

        return (lambda v, f: trimesh.remesh.subdivide_loop(v, f, iterations=LEVELS)), None
    if tool == "pymeshlab":
        return load_pymeshlab(scheme), None
    raise ValueError(f"unknown tool {tool}")


def load_pymeshlab(scheme):
    """PyMeshLab's Loop (every edge: threshold 0 %) or Catmull-Clark, numpy in and out."""
    import pymeshlab

    def run(v, f):
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=f))
        if scheme == "loop":
            ms.meshing_surface_subdivision_loop(
                loopweight="Loop", iterations=LEVELS, threshold=pymeshlab.PercentageValue(0.0))
        else:
            ms.meshing_surface_subdivision_catmull_clark(iterations=LEVELS)
        m = ms.current_mesh()
        return m.vertex_matrix(), m.face_matrix()  # face_matrix: quads as two triangles

    return run


def max_rss_mb():
    """Peak resident set size of this process's own address space so far, in MB.

    Linux's ``ru_maxrss`` carries the parent's peak over fork and exec, so a worker would
    report the driver's peak; ``VmHWM`` in ``/proc/self/status`` starts afresh at exec.
    """
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 2**10
    except OSError:
        pass
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return rss / 2**20 if sys.platform == "darwin" else rss / 2**10


def tool_version(tool):
    """The installed version of ``tool``'s distribution, or None."""
    from importlib import metadata

    try:
        return metadata.version(DISTRIBUTIONS[tool])
    except metadata.PackageNotFoundError:
        return None


def time_runs(run, v, f, repeats):
    """Runs ``run(v, f)`` up to ``repeats`` times (once if a run takes over SLOW_S)."""
    times, out = [], None
    for _ in range(repeats):
        out = None  # the previous result is freed before the next run
        start = time.perf_counter()
        vertices, faces = run(v, f)
        out = (np.asarray(vertices, np.float64), np.asarray(faces))
        times.append(time.perf_counter() - start)
        if times[-1] > SLOW_S:
            break
    return times, out


def worker(args):
    """One (tool, scheme, mesh) measurement; writes its result as JSON to ``args.result``."""
    tool, mesh = args.worker
    threads = None if args.threads is None or args.threads < 0 else args.threads
    result = {"tool": tool, "mesh": mesh, "scheme": args.scheme}
    try:
        run, result["threads"] = load_tool(tool, args.scheme, threads)
        result["version"] = tool_version(tool)
    except ImportError as error:
        result["error"] = f"not installed ({error})"
        return write_json(args.result, result)
    v = np.ascontiguousarray(np.load(os.path.join(args.workdir, f"{mesh}_v.npy")), np.float64)
    f = np.ascontiguousarray(np.load(os.path.join(args.workdir, f"{mesh}_f.npy")), np.int64)
    result["baseline_mb"] = max_rss_mb()
    try:
        times, (vertices, faces) = time_runs(run, v, f, args.repeats)
    except Exception as error:  # the tool refused the mesh: report it
        result["error"] = " ".join(f"{type(error).__name__}: {error}".split())[:300]
        return write_json(args.result, result)
    result.update(times=times, median_s=statistics.median(times), peak_mb=max_rss_mb(),
                  out_vertices=len(vertices), out_faces=len(faces), face_width=int(faces.shape[1]))
    np.save(args.result + ".v.npy", vertices)
    np.save(args.result + ".f.npy", faces)
    return write_json(args.result, result)


def write_json(path, data):
    """Writes ``data`` to ``path`` as indented JSON."""
    with open(path, "w") as out:
        json.dump(data, out, indent=1)


# --------------------------------------------------------------------------- driver


def spawn(args, workdir, mesh, tool, scheme, threads):
    """Runs one worker subprocess; returns its result (with ``error`` if it failed)."""
    path = os.path.join(workdir, f"{mesh}-{tool}-{scheme}-{threads}.json")
    cmd = [sys.executable, os.path.abspath(__file__), "--worker", tool, mesh, "--scheme", scheme,
           "--threads", str(-1 if threads is None else threads), "--repeats", str(args.repeats),
           "--workdir", workdir, "--result", path]
    base = {"tool": tool, "mesh": mesh, "scheme": scheme, "threads": threads}
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout)
    except subprocess.TimeoutExpired:
        return dict(base, error=f"timed out after {args.timeout} s")
    if proc.returncode < 0:
        import signal

        return dict(base, error=f"crashed ({signal.Signals(-proc.returncode).name})")
    if proc.returncode != 0 or not os.path.exists(path):
        tail = (proc.stderr.strip().splitlines() or ["no output"])[-1]
        return dict(base, error=" ".join(f"exit {proc.returncode}: {tail}".split())[:300])
    with open(path) as data:
        return json.load(data)


class Reference:
    """subd's output for one (mesh, scheme), against which the other outputs are compared."""

    def __init__(self, vertices, faces):
        self.vertices, self.faces = vertices, faces
        self._tree = self._sorted_faces = None

    def nearest(self, points):
        """Distance to, and index of, the nearest reference vertex of every point."""
        if self._tree is None:
            from scipy.spatial import cKDTree

            self._tree = cKDTree(self.vertices)
        return self._tree.query(points, workers=-1)  # between the timed runs: all cores

    def sorted_faces(self):
        """The reference faces as sorted vertex sets, rows in lexicographic order."""
        if self._sorted_faces is None:
            self._sorted_faces = lexsorted(np.sort(self.faces, axis=1))
        return self._sorted_faces


def lexsorted(rows):
    """``rows`` in lexicographic order."""
    return rows[np.lexsort(rows.T[::-1])]


def compare(ref, vertices, faces):
    """Max distance to subd's vertices, the fraction within AGREE, and whether the faces match."""
    if np.array_equal(vertices, ref.vertices) and np.array_equal(faces, ref.faces):
        n = len(vertices)
        return {"max_abs_delta": 0.0, "median_abs_delta": 0.0, "agree_fraction": 1.0,
                "agree_count": n, "faces_match": True, "bitwise_equal": True}
    dist, index = ref.nearest(vertices)
    agree = float((dist <= AGREE).mean())
    same = None
    bijective = len(vertices) == len(ref.vertices) and np.unique(index).size == len(index)
    if agree == 1.0 and bijective and faces.shape == ref.faces.shape:
        mapped = lexsorted(np.sort(index[faces], axis=1))
        same = bool(np.array_equal(mapped, ref.sorted_faces()))
    return {"max_abs_delta": float(dist.max()), "median_abs_delta": float(np.median(dist)),
            "agree_fraction": agree,
            "agree_count": int((dist <= AGREE).sum()), "faces_match": same}


def measure_mesh(args, workdir, mesh):
    """Every run of RUNS on ``mesh``, compared with subd's output of the same scheme."""
    rows, refs = [], {}
    for tool, scheme, threads in RUNS:
        row = spawn(args, workdir, mesh, tool, scheme, threads)
        prefix = os.path.join(workdir, f"{mesh}-{tool}-{scheme}-{threads}.json")
        if "error" not in row:
            vertices, faces = np.load(prefix + ".v.npy"), np.load(prefix + ".f.npy")
            if tool == "subd" and scheme not in refs:
                refs[scheme] = (Reference(vertices, faces), row)
            if scheme in refs:
                row.update(compare(refs[scheme][0], vertices, faces))
                row["counts_equal"] = counts_equal(row, refs[scheme][1])
            del vertices, faces
            for suffix in (".v.npy", ".f.npy"):
                os.remove(prefix + suffix)
        rows.append(row)
        took = row.get("median_s")
        print(f"[{mesh}] {tool} {scheme} threads={threads}: "
              f"{f'{took:.3f} s' if took is not None else row.get('error')}", file=sys.stderr, flush=True)
    add_ratios(rows)
    return rows


def add_ratios(rows):
    """Each row's median over the fastest subd median of its scheme."""
    for row in rows:
        best = fastest(rows, row["scheme"], subd=True)
        if best and "median_s" in row:
            row["ratio_to_subd"] = row["median_s"] / best["median_s"]


def fastest(rows, scheme, subd, equal_counts_only=False):
    """The fastest successful row of ``scheme`` by subd (``subd=True``) or by another tool."""
    ok = [r for r in rows if r["scheme"] == scheme and "median_s" in r and (r["tool"] == "subd") == subd]
    if equal_counts_only:
        ok = [r for r in ok if r.get("counts_equal")]
    return min(ok, key=lambda r: r["median_s"]) if ok else None


def counts_equal(row, ref_row):
    """Same vertex count as subd and the same faces, Catmull-Clark quads split in two allowed."""
    faces = row["out_faces"]
    if row["scheme"] == "catmull-clark" and row["face_width"] == 3 and ref_row["face_width"] == 4:
        faces /= 2  # PyMeshLab's face_matrix gives each quad as two triangles
    return row["out_vertices"] == ref_row["out_vertices"] and faces == ref_row["out_faces"]


# --------------------------------------------------------------------------- report


def number(value, spec):
    """``value`` formatted with ``spec``, or an en dash when it is missing."""
    return "–" if value is None else format(value, spec)


def note(row):
    """The remark column: the error, or what is special about the run."""
    notes = [row["error"]] if "error" in row else []
    if len(row.get("times", [])) == 1 and row.get("repeats", 1) > 1:
        notes.append(f"1 run (> {SLOW_S:.0f} s)")
    if row.get("face_width") == 3 and row["scheme"] == "catmull-clark":
        notes.append("faces: each quad as 2 triangles")
    if row.get("counts_equal") is False:
        notes.append("counts differ from subd")
    return "; ".join(notes)


def table_row(row):
    """One Markdown table line of a result row."""
    peak, base = row.get("peak_mb"), row.get("baseline_mb")
    threads = row.get("threads")
    agree = row.get("agree_fraction")
    match = {True: "yes", False: "no", None: "–"}[row.get("faces_match")]
    cells = [row["mesh"], row["tool"], row["scheme"], "default" if threads is None else str(threads),
             number(row.get("median_s"), ".3f"), str(len(row.get("times", []))) if "times" in row else "–",
             number(peak, ".0f"), number(None if peak is None else peak - base, ".0f"),
             number(row.get("out_vertices"), ","), number(row.get("out_faces"), ","),
             number(row.get("max_abs_delta"), ".2e"), "–" if agree is None else f"{100 * agree:.3f} %",
             match, number(row.get("ratio_to_subd"), ".1f"), note(row)]
    return "| " + " | ".join(cells) + " |"


def inputs_table(info):
    """Markdown table of the input meshes."""
    lines = ["| mesh | V | F | boundary edges | non-manifold edges | closed | note |",
             "|---|---:|---:|---:|---:|---|---|"]
    for name, d in info.items():
        extra = d.get("source", "")
        if "dropped_faces" in d:
            extra = f"scan less {d['dropped_faces']} faces (one per non-manifold edge)"
        elif "read_warnings" in d:
            extra += (f"; {d['read_warnings']} orientation warnings from subd.read (subd.Mesh takes"
                      " it with accept_inconsistent_orientation=True)")
        lines.append(f"| {name} | {d['vertices']:,} | {d['faces']:,} | {d['boundary_edges']} | "
                     f"{d['non_manifold_edges']} | {'yes' if d['closed'] else 'no'} | {extra} |")
    return "\n".join(lines)


def results_table(rows):
    """Markdown table of every run."""
    head = ("| mesh | tool | scheme | threads | median s | runs | peak MB | peak − baseline MB | "
            "out V | out F | max abs Δ vs subd | agree ≤ 1e-9 | faces = subd | × subd fastest | note |")
    return "\n".join([head, "|" + "---|" * 4 + "---:|" * 10 + "---|"] + [table_row(r) for r in rows])


def summary(mesh, rows, scheme="loop"):
    """The closing line of ``mesh``: the fastest other tool of equal output against subd."""
    mine = [r for r in rows if r["mesh"] == mesh]
    ours, other = fastest(mine, scheme, subd=True), fastest(mine, scheme, subd=False, equal_counts_only=True)
    label = f"{mesh}" + ("" if scheme == "loop" else f" ({scheme}, a different output)")
    if ours is None:
        return f"{label}: subd did not run ({next(r for r in mine if r['tool'] == 'subd').get('error')})"
    threads = ours["threads"]
    subd_part = f"subd: {ours['median_s']:.3f} s ({threads} thread{'s' if threads != 1 else ''})"
    if other is None:
        failed = "; ".join(f"{r['tool']}: {r.get('error', 'counts differ')}" for r in mine
                           if r["scheme"] == scheme and r["tool"] != "subd")
        return f"{label}: fastest other: none of equal output ({failed}); {subd_part}"
    line = (f"{label}: fastest other: {other['median_s']:.3f} s ({other['tool']}); {subd_part}; "
            f"subd is {other['median_s'] / ours['median_s']:.1f}× faster (target ≥ 50×)")
    if other.get("agree_fraction", 1.0) < 1.0:
        line += (f" [{other['tool']}'s positions differ from subd's at "
                 f"{other['out_vertices'] - other['agree_count']:,} vertices, max |Δ| {other['max_abs_delta']:.3g}]")
    return line


# --------------------------------------------------------------------------- main


def parse_args(argv=None):
    """Command-line options of the driver and of the worker."""
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--scan", help="a real scan (PLY/OBJ), e.g. target/xtask/bench/StanfordBunny.ply")
    p.add_argument("--repeats", type=int, default=3, help="runs per tool; the median is reported")
    p.add_argument("--grid", type=int, default=224, help="torus grid: 2 grid^2 triangles")
    p.add_argument("--json", help="also write the results to this JSON file")
    p.add_argument("--timeout", type=float, default=600, help="seconds per worker")
    p.add_argument("--worker", nargs=2, metavar=("TOOL", "MESH"), help=argparse.SUPPRESS)
    p.add_argument("--scheme", default="loop", help=argparse.SUPPRESS)
    p.add_argument("--threads", type=int, help=argparse.SUPPRESS)
    p.add_argument("--workdir", help=argparse.SUPPRESS)
    p.add_argument("--result", help=argparse.SUPPRESS)
    return p.parse_args(argv)


def main(argv=None):
    """Prepares the inputs, runs every worker, prints the tables and writes the JSON."""
    args = parse_args(argv)
    if args.worker:
        return worker(args)
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="loop_bench_") as workdir:
        info = prepare_inputs(args, workdir)
        rows = [dict(r, repeats=args.repeats) for mesh in info for r in measure_mesh(args, workdir, mesh)]
    lines = [summary(m, rows) for m in info] + [summary(m, rows, "catmull-clark") for m in info]
    versions = {r["tool"]: r["version"] for r in rows if r.get("version")}
    print(f"# Loop level {LEVELS}: subd vs trimesh, libigl, PyMeshLab\n")
    print(f"{platform.platform()}, {os.cpu_count()} CPUs, Python {platform.python_version()}, "
          f"median of up to {args.repeats} runs, times include the numpy conversions both ways; "
          + ", ".join(f"{k} {v}" for k, v in versions.items())
          + f"; load average {load_before[0]:.2f} before, {os.getloadavg()[0]:.2f} after\n")
    print(inputs_table(info) + "\n\n" + results_table(rows) + "\n")
    print("\n".join(lines))
    if args.json:
        meta = {"levels": LEVELS, "repeats": args.repeats, "platform": platform.platform(),
                "cpus": os.cpu_count(), "python": platform.python_version(), "versions": versions,
                "load_average": [load_before[0], os.getloadavg()[0]]}
        write_json(args.json, {"meta": meta, "inputs": info, "rows": rows, "summary": lines})


if __name__ == "__main__":
    main()
