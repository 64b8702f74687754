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
as with Slurm), or be given as TOML text without file references.
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
    """Test hook: the first attempt of each part raises when ``fault_dir`` is set."""
    if fault_dir is None:
        return
    marker = os.path.join(fault_dir, f"{kind}-{part}.failed-once")
    if not os.path.exists(marker):
        with open(marker, "w") as f:
            f.write("injected failure\n")
        raise RuntimeError(f"injected failure of {kind} part {part}")


def _render_task(scene, part, parts, spp, seed, threads, fault_dir):
    _maybe_fail_once(fault_dir, "render", part)
    return facette.render_part(scene, part, parts, spp=spp, seed=seed, threads=threads)


def _table_task(material, part, parts, step, samples, fault_dir):
    _maybe_fail_once(fault_dir, "table", part)
    return facette.tabulate_part(material, part, parts, step=step, samples=samples)


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
            results[index[ref]] = ray.get(ref)
        if progress:
            n = len(refs) - len(pending)
            print(f"\r{what}: {n}/{len(refs)} parts done, {time.time() - start:.1f} s", end="", file=sys.stderr)
    if progress:
        print(file=sys.stderr)
    return results


def render(scene, parts, output=None, spp=None, seed=0, address=None, num_cpus=None,
           threads_per_task=1, max_retries=3, progress=True, _fault_dir=None):
    """Renders ``scene`` (a path or TOML text) in ``parts`` Ray tasks and merges them.

    Returns the (H, W, 3) float32 image (also written to ``output``, EXR or PNG, when
    given). ``address``: an existing Ray cluster ("auto", "ray://host:10001", …); by
    default a local Ray instance with ``num_cpus`` CPUs. Each task renders with
    ``threads_per_task`` threads; a failed task is retried up to ``max_retries`` times.
    """
    if parts < 1:
        raise ValueError("`parts` must be at least 1")
    if isinstance(scene, os.PathLike) or ("\n" not in scene and not scene.lstrip().startswith("[")):
        scene = os.path.abspath(os.fspath(scene))
    ray = _init(address, num_cpus)
    task = ray.remote(num_cpus=threads_per_task, max_retries=max_retries, retry_exceptions=True)(_render_task)
    refs = [task.remote(scene, k, parts, spp, seed, threads_per_task, _fault_dir) for k in range(parts)]
    results = _gather(ray, refs, "render", progress)
    image = facette.merge_render_parts(results)
    if output is not None:
        facette.write_image(output, image, 0.0)
    return image


def tabulate(material, parts, output=None, step=5.0, samples=10_000, address=None, num_cpus=None,
             max_retries=3, progress=True, _fault_dir=None):
    """Tabulates an IL material's body term in ``parts`` Ray tasks and merges the rows;
    returns the ``.fctab`` bytes (written to ``output`` when given), byte for byte those of
    ``facette.tabulate``."""
    if parts < 1:
        raise ValueError("`parts` must be at least 1")
    ray = _init(address, num_cpus)
    task = ray.remote(num_cpus=1, max_retries=max_retries, retry_exceptions=True)(_table_task)
    refs = [task.remote(material, k, parts, step, samples, _fault_dir) for k in range(parts)]
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
    t.add_argument("--samples", type=int, default=10_000)
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
            tabulate(a.material, a.parts, a.output, step=a.step, samples=a.samples, address=a.address,
                     num_cpus=a.num_cpus, max_retries=a.max_retries, progress=not a.quiet)
            print(f"{a.output}: {a.parts} parts merged in {time.time() - start:.2f} s")
    except (ValueError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
