"""facette: microfacet materials, rendering, tables and fits, from Python.

Materials work on numpy arrays of directions in the local shading frame (z is the normal):

>>> import numpy as np, facette
>>> m = facette.Material('{type = "il", kd = [0.8, 0.4, 0.2], ni = 1.5, alpha = 0.3}')
>>> wi = np.array([[0.0, 0.0, 1.0]]); wo = np.array([[0.5, 0.0, 0.8660254]])
>>> m.eval(wi, wo).shape
(1, 3)

Renders come back as (H, W, 3) float32 arrays: ``facette.render("scenes/showcase.toml")``.
Heavy loops run in Rust with the GIL released. Errors: ``ValueError`` for bad values,
unknown names or keys and malformed files, ``OSError`` for files that cannot be read or
written — with the messages of the ``facette`` command line. See docs/python.md.
"""

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
    "__version__",
]


def _directions(a, name):
    a = _np.asarray(a, dtype=_np.float64)
    if a.ndim == 1:
        a = a.reshape(1, -1)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"`{name}` must have shape (N, 3) or (3,), got {a.shape}")
    return _np.ascontiguousarray(a)


class Material:
    """A material of docs/materials.md, from a TOML inline table (str) or a dict.

    ``Material({"type": "conductor", "material": "Au", "distribution": "ggx", "alpha": 0.3})``
    """

    def __init__(self, spec):
        self._m = _facette.Material(spec)

    @property
    def description(self):
        """The model and its parameters."""
        return self._m.description

    @property
    def is_stochastic(self):
        """Whether ``eval`` is an unbiased stochastic estimate (IL, exact Oren-Nayar)."""
        return self._m.is_stochastic

    def __repr__(self):
        return repr(self._m)

    def eval(self, wi, wo, samples=100_000, mode="radiance", seed=1):
        """f(wi, wo) per RGB channel, without the cosine: (N, 3) array.

        ``wi`` points toward the light, ``wo`` toward the viewer, both (N, 3) (or (3,)) in
        the local frame; they are normalized. Stochastic materials average ``samples``
        estimates per row (one stream seeded by ``seed``: the values ``facette eval``
        prints). ``mode`` is "radiance" or "importance" (they differ for refraction).
        """
        return self._m.eval(_directions(wi, "wi"), _directions(wo, "wo"), samples, mode, seed)

    def pdf(self, wo, wi, mode="radiance"):
        """Solid-angle density of ``sample(wo)`` producing ``wi``: (N,) array."""
        return self._m.pdf(_directions(wo, "wo"), _directions(wi, "wi"), mode)

    def sample(self, wo, u=None, mode="radiance", seed=1):
        """Samples one direction per row of ``wo``.

        Returns ``(wi (N, 3), weight (N, 3), pdf (N,), lobes)`` with weight = f·|cos θ_i|/pdf
        and ``lobes`` a list of lobe names ("glossy reflection", …, "none" for a failed
        sample). ``u``: optional (N, K) uniform numbers in [0, 1) consumed in order by each
        row's sampler (a stream seeded by ``seed`` continues past K).
        """
        wo = _directions(wo, "wo")
        if u is not None:
            u = _np.ascontiguousarray(_np.asarray(u, dtype=_np.float64))
            if u.ndim == 1:
                u = u.reshape(-1, 1) if wo.shape[0] != 1 else u.reshape(1, -1)
            if u.ndim != 2:
                raise ValueError(f"`u` must have shape (N, K), got {u.shape}")
        return self._m.sample(wo, u, mode, seed)

    def albedo(self, theta_i, samples=1_000_000, seed=1):
        """Directional reflectance and transmittance at incidences ``theta_i`` (degrees,
        scalar or list; 0-90 from above, 90-180 from below) with standard errors: a dict of
        (K, 3) arrays ``reflectance``, ``reflectance_stderr``, ``transmittance``,
        ``transmittance_stderr`` — the numbers of ``facette albedo``."""
        t = [float(x) for x in _np.atleast_1d(_np.asarray(theta_i, dtype=_np.float64))]
        return self._m.albedo(t, samples, seed)

    def to_merl(self, path, noise=0.0, seed=1):
        """Writes this material as a measured BRDF in the MERL binary format (``facette
        measure``): f at every bin centre, with multiplicative Gaussian noise of relative
        deviation ``noise``. Returns the number of valid bins."""
        return measure(self, path, noise, seed)

    def validate(self, samples=200_000, seed=1):
        """Runs every BSDF check of ``facette validate --material``; returns a
        ``ValidationReport`` (``.checks`` with name, figure and pass/fail, ``.passed``,
        ``.summary``)."""
        return self._m.validate(samples, seed)


def _scene_arg(scene):
    import os

    if isinstance(scene, os.PathLike):
        return os.fspath(scene)
    if not isinstance(scene, str):
        raise ValueError(f"`scene` must be a path or TOML text, got {type(scene).__name__}")
    return scene


def render(scene, spp=None, seed=0, threads=None, exposure=None):
    """Renders a scene (a path, or TOML text) to an (H, W, 3) float32 array of linear
    radiance times 2^exposure (the scene's film exposure by default): the values of the
    EXR ``facette render`` writes for the same scene and seed."""
    return _facette.render(_scene_arg(scene), spp, seed, threads, exposure)


def render_part(scene, part, parts, spp=None, seed=0, threads=None):
    """Part ``part`` of ``parts`` of a render, as ``.fcpart`` bytes (docs/file-formats.md)."""
    return _facette.render_part(_scene_arg(scene), part, parts, spp, seed, threads)


def render_in_parts(scene, parts, spp=None, seed=0, threads=None):
    """All ``parts`` parts rendered here and merged: what a distributed render of the same
    parts reproduces bit for bit. (H, W, 3) float32."""
    return _facette.render_in_parts(_scene_arg(scene), parts, spp, seed, threads)


def merge_render_parts(parts, exposure=None):
    """Merges render parts (bytes, any order) into an (H, W, 3) float32 array."""
    return _facette.merge_render_parts([bytes(p) for p in parts], exposure)


def write_image(path, image, exposure=0.0):
    """Writes an (H, W, 3) array as EXR (linear) or PNG (sRGB) by extension, atomically."""
    import os

    a = _np.ascontiguousarray(_np.asarray(image, dtype=_np.float32))
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"`image` must have shape (H, W, 3), got {a.shape}")
    return _facette.write_image(os.fspath(path), a, exposure)


def tabulate(material, step=5.0, samples=10_000, output=None):
    """Tabulates an IL material's body term (``facette tabulate``); returns the ``.fctab``
    bytes, also written to ``output`` when given."""
    import os

    return _facette.tabulate(material, step, samples, None if output is None else os.fspath(output))


def tabulate_part(material, part, parts, step=5.0, samples=10_000):
    """Part ``part`` of ``parts`` of a table (``facette tabulate --part``), as bytes."""
    return _facette.tabulate_part(material, part, parts, step, samples)


def merge_table_parts(parts, output=None):
    """Merges table parts (bytes, any order) into ``.fctab`` bytes (written to ``output``
    when given): byte for byte what ``tabulate`` makes."""
    import os

    return _facette.merge_table_parts([bytes(p) for p in parts], None if output is None else os.fspath(output))


def read_image(path, linear=False):
    """Reads an EXR, HDR or PNG file as an (H, W, 3) float32 array (8/16-bit files are
    decoded from sRGB unless ``linear``)."""
    import os

    return _facette.read_image(os.fspath(path), linear)


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
):
    """Fits a model to a measured BRDF in the MERL binary format (``facette fit``, same
    options and defaults): ``model`` "il", "plastic" or "kelemen"; ``distribution``
    "beckmann", "ggx" (or "gaussian" for il); ``error`` "log" or "cosine".

    Returns a dict: ``model``, ``metric``, ``parameters`` {name: value}, ``units``,
    ``rms_residual``, ``rms_relative_error``, ``evaluations``, ``seconds``, ``converged``,
    ``material`` (the fitted material as a TOML inline table, or None), ``valid_bins``,
    ``samples``. With ``output`` (.svg/.png) it also plots measured vs fitted slices at
    θ_i = 30° and 70° (IL18 Fig. 19)."""
    import os

    return _facette.fit(
        os.fspath(path),
        model,
        distribution,
        il_evaluation,
        il_samples,
        error,
        samples,
        max_theta,
        seed,
        None if output is None else os.fspath(output),
    )


def measure(material, path, noise=0.0, seed=1):
    """Writes ``material`` (a ``Material``, TOML text or dict) as a MERL file at ``path``;
    returns the number of valid bins. See ``Material.to_merl``."""
    import os

    if not isinstance(material, Material):
        material = Material(material)
    return _facette.measure(material._m, os.fspath(path), float(noise), int(seed))
