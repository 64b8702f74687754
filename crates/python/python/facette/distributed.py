"""Distributed renders and tables on Ray: one Ray task per part, retried on failure, merged
exactly (docs/scale-out.md).

Command line::

    python -m facette.distributed render SCENE --parts 64 -o OUT.exr [--address ADDR]
    python -m facette.distributed tabulate --material '{type = "il", ...}' --step 2 \
        --parts 16 -o TABLE.fctab [--address ADDR]

Each task calls the ``facette`` package in the worker (no subprocess). Part K of N renders
the sample indices s = K (mod N) of every pixel with the same per-sample random streams as
a single-process render, so the merged image is bit for bit ``facette.render_in_parts(scene,
N, seed=...)`` whatever nodes ran the parts and however often a task was retried. The scene
file and its assets must be readable at the same path on every node (a shared file system,
as with Slurm), or be given as TOML text (or a dict) without file references.

The scene (or material) is checked in the driver before any task is submitted, and a
task's user error (``ValueError``, ``OSError``: a bad scene, a missing asset on a node) is
not retried: it is raised in the driver as one line, as the same exception type. Other
failures (a lost worker, a crash) are retried up to ``max_retries`` times.
"""

import argparse
import os
import sys
import time

import facette


def _ray():
    try:
        import ray
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(
            "facette.distributed needs Ray: pip install 'ray>=2.9' (or the `distributed` extra)"
        ) from e
    return ray


def _maybe_fail_once(fault_dir, kind, part):
    """Test hook: the first attempt of each part raises when ``fault_dir`` is set; every
    attempt raises a ``ValueError`` (a user error) when ``fault_dir`` holds a file named
    ``user-error``, after leaving a file per attempt so that a test counts them."""
    if fault_dir is None:
        return
    if os.path.exists(os.path.join(fault_dir, "user-error")):
        with open(os.path.join(fault_dir, f"attempt-{kind}-{part}-{os.getpid()}-{time.monotonic_ns()}"), "w"):
            pass
        raise ValueError(f"injected user error in {kind} part {part}")
    marker = os.path.join(fault_dir, f"{kind}-{part}.failed-once")
    if not os.path.exists(marker):
        with open(marker, "w") as f:
            f.write("injected failure\n")
        raise RuntimeError(f"injected failure of {kind} part {part}")


class _UserError:
    """A task's ``ValueError``/``OSError``, returned instead of raised: Ray retries raised
    exceptions (``retry_exceptions=True``) and prints their tracebacks, while a user error
    comes out the same on every attempt and on every node."""

    def __init__(self, part, error):
        self.part = part
        self.kind = "OSError" if isinstance(error, OSError) else "ValueError"
        self.message = str(error)

    def raise_(self):
        cls = OSError if self.kind == "OSError" else ValueError
        raise cls(f"part {self.part}: {self.message}")


def _render_task(scene, part, parts, spp, seed, threads, fault_dir, defines=None):
    try:
        _maybe_fail_once(fault_dir, "render", part)
        return facette.render_part(scene, part, parts, spp=spp, seed=seed, threads=threads, defines=defines)
    except (ValueError, OSError) as e:
        return _UserError(part, e)


def _table_task(material, part, parts, step, samples, tolerance, fault_dir):
    try:
        _maybe_fail_once(fault_dir, "table", part)
        return facette.tabulate_part(material, part, parts, step=step, samples=samples, tolerance=tolerance)
    except (ValueError, OSError) as e:
        return _UserError(part, e)


def _init(address, num_cpus):
    ray = _ray()
    if not ray.is_initialized():
        if address is None:
            ray.init(num_cpus=num_cpus, include_dashboard=False, log_to_driver=False)
        else:
            ray.init(address=address, log_to_driver=False)
    return ray


def _gather(ray, refs, what, progress):
    """Waits for every task, reporting parts as they complete; returns results in part order."""
    index = {ref: k for k, ref in enumerate(refs)}
    results = [None] * len(refs)
    pending = list(refs)
    start = time.time()
    while pending:
        done, pending = ray.wait(pending, num_returns=1)
        for ref in done:
            r = ray.get(ref)
            if isinstance(r, _UserError):
                for p in pending:
                    ray.cancel(p)
                if progress:
                    print(file=sys.stderr)
                r.raise_()
            results[index[ref]] = r
        if progress:
            n = len(refs) - len(pending)
            print(f"\r{what}: {n}/{len(refs)} parts done, {time.time() - start:.1f} s", end="", file=sys.stderr)
    if progress:
        print(file=sys.stderr)
    return results


def render(scene, parts, output=None, spp=None, seed=0, address=None, num_cpus=None,
           threads_per_task=1, max_retries=3, progress=True, defines=None, _fault_dir=None):
    """Renders ``scene`` in ``parts`` Ray tasks and merges them.

    ``scene``: what ``facette.render`` takes (a path, TOML or XML text, a dict; a relative
    path is made absolute for the workers; a dict travels as TOML text), with ``defines``
    for an XML scene's ``$name`` parameters; it is loaded once in the driver first, so a
    bad scene fails before any task starts. ``spp`` and ``seed`` as for ``render``.
    Returns the (H, W, 3) float32 image (also written to ``output``, EXR or PNG, when
    given). ``address``: an existing Ray cluster ("auto", "ray://host:10001", …); by
    default a local Ray instance with ``num_cpus`` CPUs (all by default) is started
    unless Ray is already initialized. Each task renders with ``threads_per_task``
    threads and reserves as many CPUs; a failed task is retried up to ``max_retries``
    times, except on a ``ValueError``/``OSError``, raised here as one line.
    ``progress``: print the parts done on stderr.
    """
    if isinstance(parts, bool) or not isinstance(parts, int) or parts < 1:
        raise ValueError(f"`parts` = {parts!r}: must be an int of at least 1")
    spp = facette._count(spp, "spp", 1, optional=True)
    kind, value = facette._scene(scene)
    if kind == "path":
        value = os.path.abspath(value)
    elif kind == "dict":
        value, kind = facette._facette.scene_toml(value), "toml"
    # Checked here: a bad scene is one error now, not one failed task per part.
    facette._facette.check_scene(kind, value, facette._defines(defines))
    ray = _init(address, num_cpus)
    task = ray.remote(num_cpus=threads_per_task, max_retries=max_retries, retry_exceptions=True)(_render_task)
    refs = [task.remote(value, k, parts, spp, seed, threads_per_task, _fault_dir, defines) for k in range(parts)]
    results = _gather(ray, refs, "render", progress)
    image = facette.merge_render_parts(results)
    if output is not None:
        facette.write_image(output, image, 0.0)
    return image


def tabulate(material, parts, output=None, step=5.0, samples=None, address=None, num_cpus=None,
             max_retries=3, progress=True, tolerance=None, _fault_dir=None):
    """Tabulates an IL material's body term in ``parts`` Ray tasks and merges the rows;
    returns the ``.fctab`` bytes (written to ``output`` when given), byte for byte those of
    ``facette.tabulate``. ``material``: a ``Material``, TOML inline table or dict, checked
    here before any task starts; the other arguments as for ``render``."""
    if isinstance(parts, bool) or not isinstance(parts, int) or parts < 1:
        raise ValueError(f"`parts` = {parts!r}: must be an int of at least 1")
    if isinstance(material, facette.Material):
        material = material.toml
    # Checked here (a material that is not a rough IL one fails now, not in every task).
    facette._facette.check_table_material(material)
    facette._table_entries(samples, tolerance)
    ray = _init(address, num_cpus)
    task = ray.remote(num_cpus=1, max_retries=max_retries, retry_exceptions=True)(_table_task)
    refs = [task.remote(material, k, parts, step, samples, tolerance, _fault_dir) for k in range(parts)]
    results = _gather(ray, refs, "tabulate", progress)
    return facette.merge_table_parts(results, output)


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m facette.distributed", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("render", help="render a scene in parts on Ray and merge")
    r.add_argument("scene")
    r.add_argument("--parts", type=int, required=True)
    r.add_argument("-o", "--output", required=True)
    r.add_argument("--spp", type=int)
    r.add_argument("--seed", type=int, default=0)
    t = sub.add_parser("tabulate", help="tabulate an IL body term in parts on Ray and merge")
    t.add_argument("--material", required=True)
    t.add_argument("--parts", type=int, required=True)
    t.add_argument("-o", "--output", required=True)
    t.add_argument("--step", type=float, default=5.0)
    entries = t.add_mutually_exclusive_group()
    entries.add_argument("--samples", type=int)
    entries.add_argument("--tolerance", type=float, help="adaptive entries to this relative tolerance")
    for s in (r, t):
        s.add_argument("--address", help="Ray cluster address (default: start a local Ray)")
        s.add_argument("--num-cpus", type=int, help="CPUs of the local Ray instance")
        s.add_argument("--max-retries", type=int, default=3)
        s.add_argument("--quiet", action="store_true")
    r.add_argument("--threads-per-task", type=int, default=1)
    a = p.parse_args(argv)
    start = time.time()
    try:
        if a.command == "render":
            img = render(a.scene, a.parts, a.output, spp=a.spp, seed=a.seed, address=a.address,
                         num_cpus=a.num_cpus, threads_per_task=a.threads_per_task,
                         max_retries=a.max_retries, progress=not a.quiet)
            print(f"{a.output}: {img.shape[1]}×{img.shape[0]}, {a.parts} parts merged in {time.time() - start:.2f} s")
        else:
            tabulate(a.material, a.parts, a.output, step=a.step, samples=a.samples, tolerance=a.tolerance, address=a.address,
                     num_cpus=a.num_cpus, max_retries=a.max_retries, progress=not a.quiet)
            print(f"{a.output}: {a.parts} parts merged in {time.time() - start:.2f} s")
    except (ValueError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
