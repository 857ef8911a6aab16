"""Bulk assembly of a chunk's variants when the study only moves and stiffens mounts.

A study over mount stiffnesses and positions changes a few numbers of a model whose structure
stays the same. For such a chunk the variants are not assembled one by one: the mount positions
and stiffnesses of all designs are built at once from the assembled base model with the very
functions the model assembly uses (:func:`~impstab.model.mounts.ring_positions`,
:func:`~impstab.model.mounts.axial_shear_matrix`, which broadcast over designs), and the affine
forms ``K = K0 + T K1`` of all designs come from one compiled loop
(:func:`~impstab.linear.linearize.affine_forms`, the function every :class:`ModelFamily` uses).

Every design is still validated like a model file: each value by its field's schema rule, and
the model rule the changed values can break (the mounts must restrain all six rigid-body
motions) on the assembled stiffness, with a margin. A design that fails or comes near either,
or whose equilibrium would rotate under thrust (not affine), is handed back to the per-variant
path, which gives it its exact status and message (:func:`impstab.model.model_from_dict`).

Eligible: parameters among :data:`FIELDS` on a base model that is undamped, without propeller
spin, without compressible fluid and without nonlinear mount laws (their equilibrium tangent is
not affine in general). Any other study takes the per-variant path.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from ..limits import RANGES
from ..linear.batch import AffineDesign, AffineStack
from ..linear.linearize import ModelFamily, affine_forms, pack_model
from ..model.assemble import model_from_dict, unit_vector
from ..model.mounts import axial_shear_matrix, condense, ring_positions
from ..model.schema import ModelFile
from .paths import _location, resolve_path, variant_dict

__all__ = ["FIELDS", "BulkDesigns", "assemble_bulk", "variant_model"]

Array = NDArray[np.float64]

#: the fields assembled in bulk, per section (``mounts[i].position[j]`` included)
FIELDS = {
    "mount_rings": ("radius", "x", "start_angle", "k_axial", "k_shear"),
    "mounts": ("position", "k_axial", "k_shear"),
    "thrust": ("operating",),
}
#: a design whose stiffness has eigenvalues closer to singular than this (relative) goes to the
#: per-variant path, which applies the model rule (1e-9) itself
_RESTRAINT_MARGIN = 1e-8


@dataclass(frozen=True, eq=False)
class BulkDesigns:
    """The designs of a chunk assembled in bulk.

    Attributes
    ----------
    stack : AffineStack
        The matrices of the designs assembled here (``stack.rows``: their positions in the
        chunk), as :func:`~impstab.linear.batch.critical_thrust_batch` takes them.
    size : int
        Designs in the chunk; those not in ``stack.rows`` take the per-variant path.
    """

    stack: AffineStack
    size: int
    _factory: Callable[[int], ModelFamily]

    @functools.cached_property
    def designs(self) -> list[AffineDesign | None]:
        """One entry per design of the chunk: its :class:`AffineDesign`, or None for the
        per-variant path (built on first access; the study itself uses :attr:`stack`)."""
        out: list[AffineDesign | None] = [None] * self.size
        st = self.stack
        for k, j in enumerate(st.rows.tolist()):
            out[j] = AffineDesign(st.mass[k], st.k0[k], st.k1[k], float(st.thrust_max[k]), float(st.operating[k]),
                                  functools.partial(self._factory, j))
        return out


def _eligible(segments: Sequence[tuple]) -> bool:
    for seg in segments:
        fields = FIELDS.get(seg[0])
        if fields is None:
            return False
        if seg[0] == "thrust":
            if tuple(seg[1:]) != ("operating",):
                return False
        elif len(seg) < 3 or not isinstance(seg[1], int) or seg[2] not in fields:
            return False
        elif len(seg) != (4 if seg[2] == "position" else 3):
            return False
    return True


def _invalid(path, column: NDArray) -> NDArray[np.bool_]:
    """Designs whose value breaks the field's schema rule (each distinct value checked once)."""
    values, inverse = np.unique(column, return_inverse=True)
    bad = np.zeros(len(values), dtype=bool)
    for k, v in enumerate(values):
        try:
            path.check(v.item() if isinstance(v, np.generic) else v)
        except ValueError:
            bad[k] = True
    return bad[inverse.ravel()]


def _restrained(k: NDArray) -> NDArray[np.bool_]:
    """Whether each symmetric ``k (n, 6, 6)`` has ``lambda_min > _RESTRAINT_MARGIN lambda_max``.

    First one batched Cholesky factorisation of ``K - s I`` with ``s = margin tr K``: where every
    design has ``s > 0`` and the factorisation succeeds, each ``K`` is positive definite with
    ``lambda_min > s``, so ``tr K >= lambda_max`` and the rule holds for the whole chunk (0.7 us a
    design against 3.7 us for the eigenvalues). Otherwise -- some design fails or comes near, or
    the numbers overflow -- the rule itself on the eigenvalues. Both read the lower triangle.
    """
    shift = _RESTRAINT_MARGIN * np.trace(k, axis1=-2, axis2=-1)
    if np.all(np.isfinite(shift) & (shift > 0.0)):
        try:
            factor = np.linalg.cholesky(k - shift[:, None, None] * np.eye(k.shape[-1]))
        except np.linalg.LinAlgError:
            factor = None
        if factor is not None and np.isfinite(factor).all():
            return np.ones(len(k), dtype=bool)
    ev = np.linalg.eigvalsh(k)
    return ev[:, 0] > _RESTRAINT_MARGIN * ev[:, -1]


def assemble_bulk(base: dict, segments: Sequence[tuple], columns: Sequence[NDArray], name: str = "model") -> BulkDesigns | None:
    """Matrices of every design of a chunk, or None when the study is not eligible.

    Parameters
    ----------
    base : dict
        The parsed base model file.
    segments : sequence of tuple
        Each parameter's path as keys and indices.
    columns : sequence of arrays
        Each parameter's value at each design.
    name : str
        Model name (for the per-design fallback models).
    """
    if not columns or not _eligible(segments):
        return None
    try:
        doc = ModelFile.model_validate(base)
        model = model_from_dict(base, name=name)
    except Exception:  # noqa: BLE001 - the per-variant path reports it
        return None
    if model.is_damped or model.fluid.compressible or model.propeller.polar_inertia * model.propeller.speed != 0.0:
        return None
    if model.is_nonlinear or model.analysis.min_damping_ratio is not None:  # the practical onset: per model
        return None
    if model.has_massive_beams:  # internal mount dofs: per-variant path
        return None
    for seg in segments:
        if seg[0] == "mounts" and seg[2] in ("k_axial", "k_shear") and doc.mounts[seg[1]].stiffness is not None:
            return None
    n = len(columns[0])
    paths = [resolve_path(_location(tuple(seg)), base) for seg in segments]
    bad = np.zeros(n, dtype=bool)
    for path, col in zip(paths, columns):
        bad |= _invalid(path, col)
    pk = pack_model(model)
    positions = np.repeat(pk.positions[None], n, axis=0)
    stiffness = np.repeat(pk.stiffness[None], n, axis=0)
    values = {tuple(seg): np.asarray(col, dtype=float) for seg, col in zip(segments, columns)}
    first = len(doc.mounts)
    for i, ring in enumerate(doc.mount_rings):
        sl = slice(first, first + ring.count)
        first += ring.count
        get = lambda key: values.get(("mount_rings", i, key), getattr(ring, key))  # noqa: E731,B023
        if any(("mount_rings", i, key) in values for key in ("radius", "x", "start_angle")):
            positions[:, sl] = ring_positions(ring.count, get("radius"), get("x"), get("start_angle"))
        if any(("mount_rings", i, key) in values for key in ("k_axial", "k_shear")):
            k3 = axial_shear_matrix(unit_vector(ring.axis, f"mount_rings[{i}].axis"), get("k_axial"), get("k_shear"))
            stiffness[:, sl, :3, :3] = np.broadcast_to(k3, (n, 3, 3))[:, None]
    for i, mount in enumerate(doc.mounts):
        for j in range(3):
            if ("mounts", i, "position", j) in values:
                positions[:, i, j] = values[("mounts", i, "position", j)]
        if any(("mounts", i, key) in values for key in ("k_axial", "k_shear")):
            get = lambda key: values.get(("mounts", i, key), getattr(mount, key))  # noqa: E731,B023
            stiffness[:, i, :3, :3] = axial_shear_matrix(unit_vector(mount.axis, f"mounts[{i}].axis"), get("k_axial"), get("k_shear"))
    operating = values.get(("thrust", "operating"), np.full(n, np.nan if pk.operating is None else pk.operating))
    t_max = doc.analysis.thrust_max
    thrust_max = np.full(n, float(t_max)) if t_max is not None else np.minimum(10.0 * operating, RANGES["thrust"].high)
    arms = np.concatenate([np.linalg.norm(positions, axis=-1), np.full((n, 1), np.linalg.norm(pk.r_thrust))], axis=1)
    length_scale = np.maximum(arms.max(axis=1), 1e-3)
    # the model rule "the mounts restrain all six motions", on the condensed stiffness
    with np.errstate(invalid="ignore", over="ignore"):
        bad |= ~_restrained(np.nan_to_num(condense(positions, stiffness)))
    good = np.flatnonzero(~bad)
    if len(good) < n:
        positions, stiffness, length_scale = positions[good], stiffness[good], length_scale[good]
    n_good = len(good)
    # the shared fields repeated as writable C arrays (np.array copies), as a single design passes
    # them (ModelFamily): a read-only broadcast view is another argument type, for which numba
    # would compile classical_forms again
    rep = lambda a: np.array(np.broadcast_to(np.asarray(a, dtype=float), (n_good, *np.shape(a))), order="C")  # noqa: E731
    mass, _, k0, k1, _, affine = affine_forms(
        rep(pk.mass6), rep(pk.damp6), positions, stiffness, rep(np.zeros(stiffness.shape[1:])), rep(pk.e_dir),
        rep(pk.r_thrust), np.full(n_good, pk.tangency), pk.preload, length_scale,
        model.analysis.linearization == "equilibrium",
    )
    if not affine.all():
        good, mass, k0, k1 = good[affine], mass[affine], k0[affine], k1[affine]
    stack = AffineStack(good.astype(np.intp), mass, k0, k1, thrust_max[good], operating[good])
    return BulkDesigns(stack, n, functools.partial(_variant_family, base, segments, columns, name=name))


def variant_model(base: dict, segments, columns, j: int, *, name: str):
    """The model of design ``j`` of a chunk (``columns``: the chunk's parameter values), assembled
    the per-variant way: from its variant model file (raises ``ModelError``)."""
    return model_from_dict(variant_dict(base, segments, [c[j] for c in columns]), name=name)


def _variant_family(base: dict, segments, columns, j: int, *, name: str) -> ModelFamily:
    """The family of design ``j``, assembled the per-variant way (only if its engine is needed)."""
    return ModelFamily(variant_model(base, segments, columns, j, name=name))
