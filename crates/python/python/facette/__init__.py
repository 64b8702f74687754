"""facette: microfacet materials, rendering, tables and fits, from Python.

Materials work on numpy arrays of directions in the local shading frame (z is the normal),
of shape (..., 3), broadcast against each other:

>>> import numpy as np, facette
>>> m = facette.Material('{type = "il", kd = [0.8, 0.4, 0.2], ni = 1.5, alpha = 0.3}')
>>> wi = np.array([[0.0, 0.0, 1.0]]); wo = np.array([[0.5, 0.0, 0.8660254]])
>>> m.eval(wi, wo).shape
(1, 3)

Renders come back as (H, W, 3) float32 arrays: ``facette.render("scenes/showcase.toml")``.
Heavy loops run in Rust with the GIL released; Ctrl-C stops them (``KeyboardInterrupt``;
an interrupted render keeps its image so far as the exception's ``image``), and
``progress=True`` (or a callable) follows them. Errors: ``ValueError`` for bad values,
unknown names or keys and malformed files, ``OSError`` for files that cannot be read or
written — with the messages of the ``facette`` command line; ``RuntimeError`` for a bug
(a panic of the Rust code), naming the call. See docs/python.md.
"""

import functools as _functools
import os as _os
import sys as _sys
import time as _time

import numpy as _np

from . import _facette
from ._facette import ValidationCheck, ValidationReport, __version__

__all__ = [
    "Material",
    "ValidationCheck",
    "ValidationReport",
    "render",
    "render_part",
    "render_in_parts",
    "merge_render_parts",
    "write_image",
    "read_image",
    "tabulate",
    "tabulate_part",
    "merge_table_parts",
    "fit",
    "measure",
    "set_limit",
    "limits",
    "__version__",
]


def _entry(name):
    """Names a public call in the errors a bug raises: pyo3 turns a Rust panic into
    ``PanicException``, a ``BaseException`` that ``except Exception`` does not catch; the
    native calls already turn theirs into ``RuntimeError``, and this is the net under them
    (argument conversion included)."""

    def wrap(f):
        @_functools.wraps(f)
        def call(*args, **kwargs):
            try:
                return f(*args, **kwargs)
            except BaseException as e:
                if type(e).__name__ == "PanicException":
                    raise RuntimeError(f"{name}: internal error (a bug in facette; please report it): {e}") from None
                raise

        return call

    return wrap


def _count(value, name, minimum=0, optional=False):
    """An int argument ≥ ``minimum``, checked here so that a negative number is a
    ``ValueError`` naming the argument (the native layer would raise a bare
    ``OverflowError``)."""
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, _np.integer)):
        raise TypeError(f"`{name}` must be an int, got {type(value).__name__}")
    value = int(value)
    if value < minimum:
        raise ValueError(f"`{name}` = {value}: must be at least {minimum}")
    if value >= 2**64:
        raise ValueError(f"`{name}` = {value}: must be below 2**64")
    return value


def _bar(what):
    """The ``progress=True`` reporter: one line on stderr, rewritten in place."""
    start = _time.monotonic()

    def report(done, total):
        frac = done / total if total else 0.0
        end = "\n" if total and done >= total else ""
        print(f"\r{what}: {100 * frac:5.1f} % ({_time.monotonic() - start:.1f} s)", end=end, file=_sys.stderr, flush=True)

    return report


def _progress(progress, what):
    """``progress``: False/None, True (a line on stderr) or a callable ``(done, total)``."""
    if progress is None or progress is False:
        return None
    if progress is True:
        return _bar(what)
    if not callable(progress):
        raise TypeError(f"`progress` must be a bool or a callable (done, total), got {type(progress).__name__}")
    return progress


def _directions(a, name):
    a = _np.asarray(a, dtype=_np.float64)
    if a.ndim == 0 or a.shape[-1] != 3:
        raise ValueError(f"`{name}` must have shape (..., 3), got {a.shape}")
    return a


def _rows(a):
    return _np.ascontiguousarray(a.reshape(-1, 3))


def _pair(wi, wo):
    """``wi`` and ``wo`` broadcast against each other (numpy's rules on the leading axes):
    the (N, 3) rows to evaluate and the leading shape of the result."""
    wi, wo = _directions(wi, "wi"), _directions(wo, "wo")
    try:
        shape = _np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
    except ValueError:
        raise ValueError(f"`wi` of shape {wi.shape} and `wo` of shape {wo.shape} do not broadcast") from None
    wi = _np.broadcast_to(wi, shape + (3,))
    wo = _np.broadcast_to(wo, shape + (3,))
    return _rows(wi), _rows(wo), shape


_MODES = ("radiance", "importance")


class Material:
    """A material of docs/materials.md, from a TOML inline table (str), a dict (numpy
    arrays and scalars allowed as values) or another ``Material``.

    ``Material({"type": "conductor", "material": "Au", "distribution": "ggx", "alpha": 0.3})``

    Materials compare equal when their specs are equal, pickle (so they travel to Ray
    workers), and are accepted wherever a spec is (``tabulate``, ``measure``, the
    materials of a dict scene). ``spec`` is the spec as a dict, ``toml`` as a TOML inline
    table.
    """

    @_entry("facette.Material")
    def __init__(self, spec):
        self._m = _facette.Material(spec)

    @property
    def description(self):
        """The model and its parameters."""
        return self._m.description

    @property
    def is_stochastic(self):
        """Whether the model is stochastic (IL, exact Oren-Nayar): its ``eval`` an unbiased
        estimate, or, for IL with ``evaluation = "quadrature"`` and ``multiple_evaluation =
        "quadrature"``, only its sampling weights (``eval`` is then deterministic)."""
        return self._m.is_stochastic

    @property
    def spec(self):
        """The spec as a dict (a new one each time): ``Material(m.spec) == m``."""
        return self._m.spec

    @property
    def toml(self):
        """The spec as a TOML inline table (the command line's ``--material``)."""
        return self._m.toml

    def __eq__(self, other):
        if not isinstance(other, Material):
            return NotImplemented
        return self._m == other._m

    def __hash__(self):
        return hash(self._m)

    def __reduce__(self):
        return (Material, (self.spec,))

    def __repr__(self):
        return f"Material({self.toml})"

    @_entry("facette.Material.eval")
    def eval(
        self, wi, wo, samples=100_000, mode="radiance", seed=1, *, cosine=False, threads=None, progress=False,
        with_error=False,
    ):
        """f(wi, wo) per RGB channel: an array of shape ``broadcast(wi, wo)[:-1] + (3,)``.

        ``wi`` points toward the light, ``wo`` toward the viewer, both (..., 3) arrays in
        the local frame (z the normal), broadcast against each other (a (3,) direction
        against (N, 3), (H, W, 3) grids, …); they are normalized. ``cosine=False`` (the
        default) returns the BSDF alone; ``cosine=True`` multiplies it by |cos θ_i| = |wi.z|
        (Mitsuba 3's ``eval``). Materials whose ``eval`` is stochastic (``is_stochastic``,
        except IL evaluated wholly by quadrature) average ``samples`` estimates per row from
        one stream seeded by ``seed``, in row order (the values ``facette eval`` prints), on
        one thread; the others run on ``threads`` threads (all cores by default; results do not depend on it). ``mode`` is
        "radiance" or "importance" (they differ for refraction). ``progress``: True prints
        the rows done on stderr, a callable receives ``(done, total)``.

        ``with_error=True`` returns ``(f, err)``, ``err`` of ``f``'s shape: each value's
        error, as ``facette eval --with-error`` prints it — the standard error of a
        stochastic mean, the adaptive quadrature's error estimate (``evaluation =
        "quadrature"``), their root sum of squares where a value adds both, 0 for closed
        forms and tables.
        """
        samples = _count(samples, "samples", 1)
        seed = _count(seed, "seed")
        threads = _count(threads, "threads", 1, optional=True)
        wi_rows, wo_rows, shape = _pair(wi, wo)
        rows = self._m.eval(
            wi_rows, wo_rows, samples, mode, seed, threads, _progress(progress, "eval"), bool(with_error)
        )
        if cosine:
            n = _np.linalg.norm(wi_rows, axis=1, keepdims=True)
            rows = rows * _np.abs(wi_rows[:, 2:3]) / _np.where(n > 0, n, 1.0)
        f = rows[:, :3].reshape(shape + (3,))
        if with_error:
            return f, rows[:, 3:].reshape(shape + (3,))
        return f

    @_entry("facette.Material.pdf")
    def pdf(self, wi, wo, mode="radiance", *, threads=None):
        """Solid-angle density with which ``sample(wo)`` draws ``wi`` (its non-delta lobes):
        an array of shape ``broadcast(wi, wo)[:-1]``.

        The arguments come in ``eval``'s order, ``wi`` (toward the light) then ``wo``
        (toward the viewer). Earlier versions took ``pdf(wo, wi)``, the reverse: call it
        with keywords (``pdf(wi=…, wo=…)``) to be explicit.
        """
        threads = _count(threads, "threads", 1, optional=True)
        wi_rows, wo_rows, shape = _pair(wi, wo)
        return self._m.pdf(wi_rows, wo_rows, mode, threads).reshape(shape)

    @_entry("facette.Material.sample")
    def sample(self, wo, u=None, mode="radiance", seed=1, *, threads=None):
        """Samples one direction ``wi`` per direction of ``wo`` (shape (..., 3)).

        Returns ``(wi, weight, pdf, lobes)``: ``wi`` and ``weight`` of shape ``wo.shape``,
        ``pdf`` of shape ``wo.shape[:-1]``, ``lobes`` a flat list of ``wo.size // 3``
        names. ``weight`` = f·|cos θ_i|/pdf. A lobe name is its kinds joined by "+":
        "diffuse+reflection", "glossy+reflection", "glossy+transmission",
        "delta+reflection", "delta+transmission", or "none" for a failed sample (then
        ``wi`` = 0, weight 0, pdf 0). ``u``: optional uniform numbers in [0, 1) of shape
        ``wo.shape[:-1] + (K,)`` consumed in order by each direction's sampler (a stream
        seeded by ``seed`` and the row index continues past K). Rows are independent:
        ``threads`` (all cores by default) does not change the result.
        """
        seed = _count(seed, "seed")
        threads = _count(threads, "threads", 1, optional=True)
        wo = _directions(wo, "wo")
        shape = wo.shape[:-1]
        wo_rows = _rows(wo)
        if u is not None:
            u = _np.asarray(u, dtype=_np.float64)
            if u.ndim == 1 and shape == (1,) or u.ndim == 1 and shape == ():
                u = u.reshape(1, -1)
            elif u.ndim == len(shape) + 1 and u.shape[:-1] == shape:
                u = u.reshape(-1, u.shape[-1])
            elif u.ndim == 1 and len(shape) == 1:
                u = u.reshape(-1, 1)
            else:
                raise ValueError(f"`u` must have shape {shape + ('K',)}, got {u.shape}")
            u = _np.ascontiguousarray(u)
        wi, weight, pdf, lobes = self._m.sample(wo_rows, u, mode, seed, threads)
        return wi.reshape(shape + (3,)), weight.reshape(shape + (3,)), pdf.reshape(shape), lobes

    @_entry("facette.Material.albedo")
    def albedo(self, theta_i, samples=1_000_000, seed=1, *, threads=None, progress=False):
        """Directional reflectance and transmittance at incidences ``theta_i`` (degrees,
        scalar or list; 0-90 from above, 90-180 from below) with standard errors: a dict of
        (K, 3) arrays ``reflectance``, ``reflectance_stderr``, ``transmittance``,
        ``transmittance_stderr`` — the numbers of ``facette albedo``. The angles run in
        parallel on ``threads`` threads (all cores by default; results do not depend on
        it); ``progress`` counts angles done."""
        samples = _count(samples, "samples", 100)
        seed = _count(seed, "seed")
        threads = _count(threads, "threads", 1, optional=True)
        t = [float(x) for x in _np.atleast_1d(_np.asarray(theta_i, dtype=_np.float64)).ravel()]
        return self._m.albedo(t, samples, seed, threads, _progress(progress, "albedo"))

    @_entry("facette.Material.to_merl")
    def to_merl(self, path, noise=0.0, seed=1):
        """Writes this material as a measured BRDF in the MERL binary format (``facette
        measure``): f at every bin centre, with multiplicative Gaussian noise of relative
        deviation ``noise``. Returns the number of valid bins."""
        return measure(self, path, noise, seed)

    @_entry("facette.Material.validate")
    def validate(self, samples=200_000, seed=1, *, progress=False):
        """Runs every BSDF check of ``facette validate --material``; returns a
        ``ValidationReport`` (``.checks`` with name, figure and pass/fail, ``.passed``,
        ``.summary``). ``samples``: chi-square samples per test (at least 1000);
        ``progress`` counts steps (one per incidence, then the reciprocity and NaN/Inf
        sweeps)."""
        samples = _count(samples, "samples", 1000)
        seed = _count(seed, "seed")
        return self._m.validate(samples, seed, _progress(progress, "validate"))


def _scene(scene):
    """``(kind, value)`` of a scene argument: "path" for a path-like or a str naming an
    existing file (or looking like a file name: one line without ``=``, ``[`` or ``<``);
    "xml" for Mitsuba XML text (starts with ``<``); "dict" for a dict; "toml" for any
    other str (TOML text, one line or many)."""
    if isinstance(scene, _os.PathLike):
        return "path", _os.fspath(scene)
    if isinstance(scene, dict):
        return "dict", scene
    if not isinstance(scene, str):
        raise TypeError(f"`scene` must be a path, TOML or XML text, or a dict, got {type(scene).__name__}")
    text = scene.strip()
    if "\n" not in text and _os.path.isfile(text):
        return "path", scene
    if text.startswith("<"):
        return "xml", scene
    if "\n" in text or "=" in text or text.startswith("["):
        return "toml", scene
    return "path", scene


def _defines(defines):
    if defines is None:
        return None
    if not isinstance(defines, dict):
        raise TypeError(f"`defines` must be a dict {{name: value}}, got {type(defines).__name__}")
    return [(str(k), str(v)) for k, v in defines.items()]


def _scene_args(scene, defines, width, height):
    kind, value = _scene(scene)
    return kind, value, _defines(defines), _count(width, "width", 1, optional=True), _count(height, "height", 1, optional=True)


@_entry("facette.render")
def render(scene, spp=None, seed=0, threads=None, exposure=None, *, defines=None, width=None, height=None,
           time_limit=None, progress=False):
    """Renders a scene to an (H, W, 3) float32 array of linear radiance times 2^exposure
    (the scene's film exposure by default): the values of the EXR ``facette render``
    writes for the same scene and seed.

    ``scene``: a path (TOML, or Mitsuba 3 XML by its ``.xml`` extension), TOML text, a dict
    in the TOML grammar (docs/scene-format.md; ``Material`` objects allowed as materials)
    or Mitsuba XML text (starting with ``<``; its file references must be absolute).
    ``defines``: ``{name: value}`` for an XML scene's ``$name`` parameters (the command
    line's ``-D``). ``spp``, ``width``, ``height`` override the scene's film (width and
    height for TOML scenes); ``threads``: worker threads (all cores by default; the image
    does not depend on it); ``time_limit``: seconds after which the render stops with the
    samples so far (the first pass always completes). ``progress``: True prints the
    progress on stderr, a callable receives ``(samples done, samples)``.

    Ctrl-C stops the render within a fraction of a second and raises
    ``KeyboardInterrupt``, whose ``image`` attribute holds the image so far (each pixel the
    mean of the samples it got).
    """
    kind, value, d, w, h = _scene_args(scene, defines, width, height)
    return _facette.render(kind, value, _count(spp, "spp", 1, optional=True), _count(seed, "seed"),
                           _count(threads, "threads", 1, optional=True), exposure, d, w, h, time_limit,
                           _progress(progress, "render"))


@_entry("facette.render_part")
def render_part(scene, part, parts, spp=None, seed=0, threads=None, *, defines=None, width=None, height=None,
                progress=False):
    """Part ``part`` of ``parts`` of a render, as ``.fcpart`` bytes (docs/file-formats.md).
    ``scene`` and the options as for ``render``; an interrupted part raises
    ``KeyboardInterrupt`` and is not returned (a part is only ever complete)."""
    kind, value, d, w, h = _scene_args(scene, defines, width, height)
    return _facette.render_part(kind, value, _count(part, "part"), _count(parts, "parts", 1),
                                _count(spp, "spp", 1, optional=True), _count(seed, "seed"),
                                _count(threads, "threads", 1, optional=True), d, w, h, _progress(progress, "render part"))


@_entry("facette.render_in_parts")
def render_in_parts(scene, parts, spp=None, seed=0, threads=None, *, defines=None, width=None, height=None,
                    progress=False):
    """All ``parts`` parts rendered here and merged: what a distributed render of the same
    parts reproduces bit for bit. (H, W, 3) float32."""
    kind, value, d, w, h = _scene_args(scene, defines, width, height)
    return _facette.render_in_parts(kind, value, _count(parts, "parts", 1), _count(spp, "spp", 1, optional=True),
                                    _count(seed, "seed"), _count(threads, "threads", 1, optional=True), d, w, h,
                                    _progress(progress, "render in parts"))


@_entry("facette.merge_render_parts")
def merge_render_parts(parts, exposure=None):
    """Merges render parts (bytes, any order) into an (H, W, 3) float32 array."""
    return _facette.merge_render_parts([bytes(p) for p in parts], exposure)


@_entry("facette.write_image")
def write_image(path, image, exposure=0.0):
    """Writes an (H, W, 3) array as EXR (linear) or PNG (sRGB) by extension, atomically."""
    a = _np.ascontiguousarray(_np.asarray(image, dtype=_np.float32))
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"`image` must have shape (H, W, 3), got {a.shape}")
    return _facette.write_image(_os.fspath(path), a, exposure)


def _material_arg(material):
    return material._m if isinstance(material, Material) else material


@_entry("facette.tabulate")
def _table_entries(samples, tolerance):
    """(samples, tolerance) for the extension: QMC entries (10 000 microfacets unless
    ``samples`` says otherwise), or adaptive quadrature to ``tolerance``; not both."""
    if tolerance is None:
        return _count(10_000 if samples is None else samples, "samples", 1), None
    if samples is not None:
        raise ValueError("`samples` (QMC entries) and `tolerance` (adaptive entries) are exclusive: give one")
    if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)):
        raise ValueError(f"`tolerance` = {tolerance!r}: must be a number")
    return 1, float(tolerance)


@_entry("facette.tabulate")
def tabulate(material, step=5.0, samples=None, output=None, *, tolerance=None, progress=False):
    """Tabulates an IL material's body term (``facette tabulate``); returns the ``.fctab``
    bytes, also written to ``output`` when given. Entries are QMC estimates of ``samples``
    microfacets (10 000 by default) or, with ``tolerance``, deterministic adaptive quadrature
    to that relative tolerance (``--tolerance``). ``progress`` counts table rows."""
    n, tol = _table_entries(samples, tolerance)
    return _facette.tabulate(_material_arg(material), step, n,
                             None if output is None else _os.fspath(output), _progress(progress, "tabulate"), tol)


@_entry("facette.tabulate_part")
def tabulate_part(material, part, parts, step=5.0, samples=None, *, tolerance=None, progress=False):
    """Part ``part`` of ``parts`` of a table (``facette tabulate --part``), as bytes;
    ``samples`` and ``tolerance`` as for ``tabulate``."""
    n, tol = _table_entries(samples, tolerance)
    return _facette.tabulate_part(_material_arg(material), _count(part, "part"), _count(parts, "parts", 1), step,
                                  n, _progress(progress, "tabulate part"), tol)


@_entry("facette.merge_table_parts")
def merge_table_parts(parts, output=None):
    """Merges table parts (bytes, any order) into ``.fctab`` bytes (written to ``output``
    when given): byte for byte what ``tabulate`` makes."""
    return _facette.merge_table_parts([bytes(p) for p in parts], None if output is None else _os.fspath(output))


@_entry("facette.read_image")
def read_image(path, linear=False):
    """Reads an EXR, HDR or PNG file as an (H, W, 3) float32 array (8/16-bit files are
    decoded from sRGB unless ``linear``)."""
    return _facette.read_image(_os.fspath(path), linear)


@_entry("facette.fit")
def fit(
    path,
    model="il",
    distribution="beckmann",
    il_evaluation="quadrature",
    il_samples=128,
    error="log",
    samples=4000,
    max_theta=80.0,
    seed=1,
    output=None,
    *,
    progress=False,
):
    """Fits a model to a measured BRDF in the MERL binary format (``facette fit``, same
    options and defaults): ``model`` "il", "plastic" or "kelemen"; ``distribution``
    "beckmann", "ggx" (or "gaussian" for il); ``il_evaluation`` and ``il_samples``: how an
    IL model's body term is evaluated; ``error`` "log" or "cosine"; ``samples``: BRDF
    samples the fit uses; ``max_theta``: the largest θ (degrees) of the samples; ``seed``.

    Returns a dict: ``model``, ``metric``, ``parameters`` {name: value}, ``units``,
    ``rms_residual``, ``rms_relative_error``, ``evaluations``, ``seconds``, ``converged``,
    ``material`` (the fitted material as a TOML inline table, or None), ``valid_bins``,
    ``samples``. With ``output`` (.svg/.png) it also plots measured vs fitted slices at
    θ_i = 30° and 70° (IL18 Fig. 19). ``progress``: the fit reports only its end."""
    return _facette.fit(
        _os.fspath(path),
        model,
        distribution,
        il_evaluation,
        _count(il_samples, "il_samples", 1),
        error,
        _count(samples, "samples"),
        max_theta,
        _count(seed, "seed"),
        None if output is None else _os.fspath(output),
        _progress(progress, "fit"),
    )


@_entry("facette.measure")
def measure(material, path, noise=0.0, seed=1):
    """Writes ``material`` (a ``Material``, TOML text or dict) as a MERL file at ``path``;
    returns the number of valid bins. See ``Material.to_merl``."""
    if not isinstance(material, Material):
        material = Material(material)
    return _facette.measure(material._m, _os.fspath(path), float(noise), _count(seed, "seed"))


def set_limit(key, value):
    """Raises (or lowers) a resource limit for this process, as the CLI's ``--limit
    KEY=N``: ``set_limit("mesh-elements", 2_000_000_000)``. Ray workers are other
    processes: give them ``FACETTE_LIMITS="mesh-elements=2000000000"`` in their
    environment instead (it is read at import). An unknown key, a fixed limit or a value
    above the limit's ceiling raises ``ValueError``."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"set_limit: the value of `{key}` must be an integer, got {value!r}")
    _facette.set_limit(f"{key}={value}")


def limits():
    """Every resource limit as a dict ``key -> (value in force, default, ceiling, what)``."""
    return {k: (v, d, c, w) for (k, v, d, c, w) in _facette.limits()}
