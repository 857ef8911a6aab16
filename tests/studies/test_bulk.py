"""Bulk assembly of a chunk's variants against the per-variant route (model file -> model -> family)."""

import copy

import numpy as np
import pytest
from conftest import asymmetric_model_dict, ring_model_dict

import impstab
from impstab.errors import ModelError
from impstab.linear.batch import KINDS, STATUSES, AffineDesign, critical_thrust_batch
from impstab.linear.linearize import ModelFamily
from impstab.model import model_from_dict
from impstab.studies.bulk import assemble_bulk
from impstab.studies.evaluate import ChunkTask, evaluate_chunk, variant_dict


def _mixed_base(linearization="classical"):
    """A ring plus two single paper mounts, no dampers: every bulk field has somewhere to go."""
    d = asymmetric_model_dict(analysis={"thrust_max": 60000.0, "linearization": linearization})
    d["mounts"] = [dict(m) for m in d["mounts"][1:3]]
    d["mount_rings"] = [{"count": 4, "radius": 0.2, "x": -0.1, "start_angle": 10.0, "axis": [1.0, 0.0, 0.1],
                         "k_axial": 8e4, "k_shear": 1.5e4},
                        {"count": 3, "radius": 0.12, "x": 0.35, "k_axial": 5e4, "k_shear": 1e4}]
    return d


PATHS = [
    (("mount_rings", 0, "radius"), 0.1, 0.3),
    (("mount_rings", 0, "x"), -0.3, 0.2),
    (("mount_rings", 0, "start_angle"), -90.0, 90.0),
    (("mount_rings", 0, "k_axial"), 3e4, 2e5),
    (("mount_rings", 0, "k_shear"), 5e3, 4e4),
    (("mount_rings", 1, "x"), 0.25, 0.45),
    (("mount_rings", 1, "k_shear"), 5e3, 2e4),
    (("mounts", 0, "position", 0), 0.1, 0.4),
    (("mounts", 1, "position", 2), -0.2, 0.0),
    (("mounts", 0, "k_axial"), 5e4, 2e5),
    (("mounts", 1, "k_shear"), 5e3, 3e4),
    (("thrust", "operating"), 1000.0, 5000.0),
]


def _columns(rng, n, paths=PATHS):
    return [p[0] for p in paths], [rng.uniform(p[1], p[2], n) for p in paths]


def _fluid_base():
    """Incompressible added mass of a baffled cylinder, no thrust_max (10x the operating thrust)."""
    d = _mixed_base()
    d["hull"] = {"radius": 0.25, "length": 2.0, "center": [-0.3, 0.0, 0.0]}
    d["fluid"] = {"model": "baffled-cylinder", "density": 1025.0}
    d["analysis"] = {"linearization": "classical"}
    return d


@pytest.mark.parametrize("base", [_mixed_base(), _fluid_base()], ids=["mounts", "fluid"])
def test_matrices_equal_the_per_variant_assembly(base):
    segs, cols = _columns(np.random.default_rng(1), 25)
    bulk = assemble_bulk(base, segs, cols)
    assert bulk is not None and all(isinstance(d, AffineDesign) for d in bulk.designs)
    for j, design in enumerate(bulk.designs):
        model = model_from_dict(variant_dict(base, segs, [c[j] for c in cols]))
        m, d, g, k0, k1 = ModelFamily(model).affine_parts()
        assert not d.any() and not g.any()
        # the same functions on the same numbers: equal to the last bit but for summation order
        np.testing.assert_allclose(design.mass, m, rtol=0, atol=1e-15 * np.abs(m).max())
        np.testing.assert_allclose(design.k0, k0, rtol=0, atol=1e-14 * np.abs(k0).max())
        np.testing.assert_allclose(design.k1, k1, rtol=0, atol=1e-14 * np.abs(k1).max())
        assert design.thrust_max == model.analysis.thrust_max
        assert design.operating == model.thrust.operating
        # the fallback family is the variant's own
        np.testing.assert_array_equal(design.family().affine_parts()[3], k0)


def test_critical_thrust_equals_the_single_model_function():
    base = _mixed_base()
    segs, cols = _columns(np.random.default_rng(2), 12)
    task = ChunkTask(0, (12,), base, tuple(segs), tuple(cols), ("critical_thrust", "kind", "frequency_hz", "margin"))
    got = evaluate_chunk(task)
    assert (got.data["status"] == 0).all()
    found = 0
    for j in range(12):
        ref = impstab.critical_thrust(model_from_dict(variant_dict(base, segs, [c[j] for c in cols])))
        if ref.thrust is None:
            assert np.isnan(got.data["critical_thrust"][j]) and got.data["kind"][j] == 0
            continue
        found += 1
        assert abs(got.data["critical_thrust"][j] - ref.thrust) <= 1e-10 * ref.thrust
        assert abs(got.data["frequency_hz"][j] - ref.omega / (2 * np.pi)) <= 1e-10 * ref.omega
        assert abs(got.data["margin"][j] - ref.margin) <= 1e-10 * ref.margin
    assert found >= 6


def test_invalid_and_unrestrained_designs_get_the_model_file_message():
    base = ring_model_dict()
    segs = [("mount_rings", 0, "k_shear"), ("mount_rings", 0, "radius")]
    cols = [np.array([2e4, -1.0, 0.0, 2e4, 2e4]), np.array([0.15, 0.15, 0.15, 0.0, np.inf])]
    bulk = assemble_bulk(base, segs, cols)
    assert isinstance(bulk.designs[0], AffineDesign)
    assert bulk.designs[1:] == [None] * 4
    got = evaluate_chunk(ChunkTask(0, (5,), base, tuple(segs), tuple(cols), ("critical_thrust",)))
    assert got.data["status"][0] == 0
    for j in range(1, 5):
        with pytest.raises(ModelError) as err:
            model_from_dict(variant_dict(base, segs, [c[j] for c in cols]))
        assert got.data["status"][j] == STATUSES.index("invalid")
        assert got.data["message"][j] == str(err.value)
    assert "restrain" in got.data["message"][2]


def test_rotating_equilibrium_takes_the_per_variant_path():
    base = _mixed_base("equilibrium")
    segs, cols = _columns(np.random.default_rng(3), 4, PATHS[:2])
    bulk = assemble_bulk(base, segs, cols)
    assert bulk.designs == [None] * 4  # off-axis thrust: the body rotates, K is not affine in T
    sym = ring_model_dict()
    bulk = assemble_bulk(sym, [("mount_rings", 0, "x")], [np.array([0.1, 0.2])])
    assert all(isinstance(d, AffineDesign) for d in bulk.designs)


@pytest.mark.parametrize(
    "base,seg",
    [
        (ring_model_dict(), ("body", "mass")),
        (ring_model_dict(), ("mount_rings", 0, "count")),
        (ring_model_dict(), ("mount_rings", 0, "c_shear")),
        (ring_model_dict(), ("thrust", "tangency")),
        (ring_model_dict(propeller={"polar_inertia": 0.5, "speed": 100.0}), ("mount_rings", 0, "x")),
        (asymmetric_model_dict(), ("mounts", 1, "k_shear")),  # damped base
    ],
)
def test_other_studies_are_not_assembled_in_bulk(base, seg):
    assert assemble_bulk(base, [seg], [np.array([1.0, 2.0])]) is None


def test_a_full_stiffness_mount_is_not_assembled_in_bulk():
    base = asymmetric_model_dict()
    for m in base["mounts"]:
        m.pop("c_axial", None)
        m.pop("c_shear", None)
    bad = copy.deepcopy(base)
    bad["mounts"][3]["k_axial"] = 1.0  # not read: the mount has a 6x6 stiffness
    assert assemble_bulk(base, [("mounts", 3, "k_axial")], [np.array([1.0, 2.0])]) is None
    assert assemble_bulk(base, [("mounts", 0, "k_axial")], [np.array([1e5, 2e5])]) is not None


def test_a_bulk_design_that_needs_its_own_engine_builds_its_model():
    # vectorized=False sends every design to its own engine: the family comes from the factory
    base = _mixed_base()
    segs, cols = _columns(np.random.default_rng(4), 3)
    designs = assemble_bulk(base, segs, cols).designs
    got = critical_thrust_batch(designs, vectorized=False)
    for j in range(3):
        ref = impstab.critical_thrust(model_from_dict(variant_dict(base, segs, [c[j] for c in cols])))
        assert got.status[j] == 0 and KINDS[got.kind[j]] == ref.kind
        if ref.thrust is None:
            assert np.isnan(got.thrust[j])
        else:
            assert abs(got.thrust[j] - ref.thrust) <= 1e-10 * ref.thrust


def test_postcritical_outputs_of_designs_assembled_in_bulk_are_those_of_their_models():
    # the post-critical analysis needs the model: a design assembled in bulk is built as one for it
    # (it raised AttributeError on the matrices alone)
    from impstab.postcritical import propulsor_postcritical

    base = _mixed_base()
    segs = [("mount_rings", 0, "k_axial"), ("mount_rings", 0, "k_shear")]
    cols = [np.array([3e4, 1e5]), np.array([1e4, 2e4])]  # both flutter (checked below)
    assert len(assemble_bulk(base, segs, cols).stack) == 2
    got = evaluate_chunk(ChunkTask(0, (2,), base, tuple(segs), tuple(cols),
                                   ("critical_thrust", "lyapunov_coefficient", "bifurcation")))
    assert (got.data["status"] == 0).all()
    for j in range(2):
        ref = propulsor_postcritical(model_from_dict(variant_dict(base, segs, [c[j] for c in cols])), branch=False)
        # undamped (as every design assembled in bulk): the merging of two frequencies, no Hopf point
        assert ref.bifurcation == "degenerate" and ref.lyapunov_coefficient is None
        assert got.data["bifurcation"][j] == ref.bifurcation
        assert np.isnan(got.data["lyapunov_coefficient"][j])
        assert got.data["critical_thrust"][j] == pytest.approx(ref.critical_thrust, rel=1e-9)


def test_a_stack_and_separate_designs_in_one_batch():
    # the study's stacked designs and AffineDesign entries of the same batch are one stack
    base = _mixed_base()
    segs, cols = _columns(np.random.default_rng(6), 4)
    bulk = assemble_bulk(base, segs, cols)
    mixed = [None, None] + bulk.designs[2:]
    got = critical_thrust_batch(mixed, affine=bulk.stack.take(slice(0, 2)))
    ref = critical_thrust_batch(bulk.designs)
    np.testing.assert_array_equal(got.status, 0)
    np.testing.assert_array_equal(got.thrust, ref.thrust)
    np.testing.assert_array_equal(got.kind, ref.kind)


def _with_eigenvalues(rng, values):
    q, _ = np.linalg.qr(rng.standard_normal((6, 6)))
    return (q * np.asarray(values, dtype=float)) @ q.T


@pytest.mark.parametrize("case", ["well restrained", "one free motion", "near the margin", "within tr K of it",
                                  "indefinite", "negative trace", "huge numbers"])
def test_restraint_check_is_the_eigenvalue_rule(case):
    # the batched Cholesky shortcut says "all restrained" only where the rule (lambda_min >
    # margin lambda_max) holds for every design, else the rule itself decides
    from impstab.studies.bulk import _RESTRAINT_MARGIN, _restrained

    rng = np.random.default_rng(7)
    stack = [_with_eigenvalues(rng, rng.uniform(1e3, 1e6, 6)) for _ in range(40)]
    odd = {"well restrained": None,
           "one free motion": [0.0, 1e4, 2e4, 3e4, 4e4, 5e4],
           "near the margin": [0.5e-8, 1, 1, 1, 1, 1],         # below the margin: not restrained
           "within tr K of it": [2e-8, 1, 1, 1, 1, 1],        # restrained, but lambda_min < margin tr K
           "indefinite": [-1.0, 1e4, 1e4, 1e4, 1e4, 1e4],
           "negative trace": [-1e4, -1e4, -1e4, 1e-3, 1e-3, 1e-3]}.get(case)
    if odd is not None:
        stack[17] = _with_eigenvalues(rng, odd)
    k = np.array(stack)
    if case == "huge numbers":  # entries near the largest float (stiffness files are capped far below)
        k[5] *= 1e300
    got = _restrained(k)
    with np.errstate(over="ignore", invalid="ignore"):
        ev = np.linalg.eigvalsh(k)
    rule = ev[:, 0] > _RESTRAINT_MARGIN * ev[:, -1]
    np.testing.assert_array_equal(got, rule)
    assert got.all() == (case in ("well restrained", "within tr K of it", "huge numbers"))
