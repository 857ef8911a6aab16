"""The paper's modal form (eq. 22-25) is an exact change of basis when every mode is kept."""

import numpy as np
import pytest
from conftest import asymmetric_model_dict

from impstab import linearize
from impstab.linear.modal_form import modal_form
from impstab.model import model_from_dict


def sorted_eigs(lam):
    return lam[np.lexsort((np.round(lam.imag, 8), np.round(lam.real, 8)))]


@pytest.mark.parametrize("thrust", [0.0, 3000.0, 9000.0])
def test_full_modal_form_reproduces_full_model(thrust):
    d = asymmetric_model_dict()
    d["propeller"] = {"polar_inertia": 0.03, "speed": 120.0}
    model = model_from_dict(d)
    mf = modal_form(model)
    assert not mf.truncated and mf.n_modes == 6
    full = np.linalg.eigvals(linearize(model, thrust, "classical").state_matrix())
    modal = mf.eigenvalues(thrust)
    assert np.allclose(np.sort_complex(full), np.sort_complex(modal), rtol=1e-9, atol=1e-9 * np.abs(full).max())


def test_mass_normalisation_and_truncation():
    model = model_from_dict(asymmetric_model_dict())
    mf = modal_form(model, n_modes=4, modal_damping=True)
    m = linearize(model, 0.0, "classical").M
    assert np.allclose(mf.phi.T @ m @ mf.phi, np.eye(4), atol=1e-12)
    assert mf.truncated and mf.eigenvalues(0.0).size == 8
    assert np.allclose(mf.d, np.diag(np.diag(mf.d)))
