"""Shared fixtures: example paths and model builders."""

from __future__ import annotations

from pathlib import Path

from impstab._blas import prefer_single_thread

prefer_single_thread()  # as the command line does, before numpy loads (see impstab._blas)

import pytest  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

#: the modules that take longest (2 to 40 s of one worker each, measured on two cores), longest
#: first: ``make test`` keeps each module on one worker (``--dist loadscope``), and a long module
#: handed out last leaves the other worker idle until it ends (every module of 2 s or more is
#: named, so that what is left at the end is a second or less)
LONGEST_FIRST = (
    "studies/test_store_faults_kill.py", "test_docs_commands.py", "studies/test_store_faults.py", "test_jit.py",
    "postcritical/test_propulsor.py", "report/test_report_content.py", "postcritical/test_propulsor_beam_mounts.py",
    "studies/test_dask.py", "report/test_report_browser.py", "studies/test_store_resume.py",
    "postcritical/test_onset_labels.py", "postcritical/test_propulsor_viscoelastic.py", "test_startup.py",
    "studies/test_statistics.py", "dynamics/test_dyn_beam_mounts.py", "studies/test_store_faults_disk.py",
    "plot/test_style_and_files.py", "dynamics/test_dyn_mount_laws.py", "postcritical/test_continuation.py",
    "linear/test_large_damped.py", "fuzz/test_fuzz_model_files.py", "fuzz/test_fuzz_arguments.py",
    "dynamics/test_dyn_integrators.py", "dynamics/test_dyn_viscoelastic.py",
)


def pytest_collection_modifyitems(config, items):
    """The longest modules first (a stable sort: the rest, and the tests in a module, keep their order)."""
    rank = {name: k for k, name in enumerate(LONGEST_FIRST)}
    here = Path(__file__).resolve().parent

    def place(item) -> int:
        path = item.path.resolve()  # items from outside tests/ (doctests of src/, say) keep their order
        return rank.get(path.relative_to(here).as_posix(), len(rank)) if path.is_relative_to(here) else len(rank)

    items.sort(key=place)


@pytest.fixture
def examples() -> Path:
    return EXAMPLES


def ring_model_dict(**over) -> dict:
    """The symmetric three-mount ring as a model-file dict, with top-level overrides."""
    d = {
        "schema_version": 1,
        "name": "ring",
        "body": {"mass": 100.0, "inertia": [1.0, 6.0, 6.0]},
        "mount_rings": [
            {"count": 3, "radius": 0.15, "x": 0.3, "start_angle": 90.0, "k_axial": 1.0e5, "k_shear": 2.0e4}
        ],
        "thrust": {"operating": 2000.0},
        "analysis": {"thrust_max": 30000.0},
    }
    d.update(over)
    return d


def asymmetric_model_dict(**over) -> dict:
    """An asymmetric layout: tilted axes, a full 6x6 mount, cg offset, off-axis thrust."""
    d = {
        "schema_version": 1,
        "name": "asym",
        "body": {"mass": 120.0, "cg": [0.05, 0.01, -0.005], "inertia": [[1.4, 0.05, 0.0], [0.05, 7.5, 0.1], [0.0, 0.1, 7.0]]},
        "mounts": [
            {"position": [0.30, 0.16, 0.02], "axis": [1.0, 0.1, 0.0], "k_axial": 1.2e5, "k_shear": 2.2e4, "c_axial": 40.0, "c_shear": 8.0},
            {"position": [0.28, -0.05, 0.15], "axis": [1.0, 0.0, 0.15], "k_axial": 0.9e5, "k_shear": 1.8e4},
            {"position": [0.33, -0.09, -0.13], "axis": [1.0, -0.05, -0.05], "k_axial": 1.0e5, "k_shear": 2.0e4},
            {
                "position": [-0.20, 0.0, -0.14],
                "stiffness": [
                    [3.0e4, 0, 0, 0, 500.0, 0],
                    [0, 1.0e4, 0, -300.0, 0, 0],
                    [0, 0, 1.0e4, 0, 0, 0],
                    [0, -300.0, 0, 800.0, 0, 0],
                    [500.0, 0, 0, 0, 900.0, 0],
                    [0, 0, 0, 0, 0, 700.0],
                ],
            },
        ],
        "thrust": {"point": [-0.1, 0.01, 0.02], "direction": [1.0, 0.01, -0.02], "tangency": 0.8, "operating": 3000.0},
        "analysis": {"thrust_max": 60000.0},
    }
    d.update(over)
    return d
