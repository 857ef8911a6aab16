"""The paper's modal form (eq. 22-25): ``(lambda^2 I + lambda d + omega0^2 - P b) zeta = 0``.

Mass-normalised modes ``Phi`` of the undamped problem at zero thrust (``Phi^T M Phi = I``,
``Phi^T K_c Phi = omega0^2``); with the classical stiffness ``K(P) = K_c - P K_G``,
``b = Phi^T K_G Phi``, ``d = Phi^T D Phi`` (its diagonal with ``modal_damping=True``) and
``g = Phi^T G Phi``. Keeping every mode it is an exact change of basis; a truncated form keeps
the ``n_modes`` lowest and says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.typing import NDArray

from ..errors import ModelError
from ..model.model import Model
from .eigen import state_matrices
from .linearize import ModelFamily

__all__ = ["ModalForm", "modal_form"]

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class ModalForm:
    """Modal equations of the classical linearization.

    Attributes
    ----------
    omega0 : (k,) natural frequencies at zero thrust (rad/s)
    phi : (6, k) mass-normalised mode shapes
    b : (k, k) modal load matrix, ``Phi^T K_G Phi`` with ``K(P) = K_c - P K_G``
    d : (k, k) modal damping
    n_modes : int
    truncated : bool
    """

    omega0: Array
    phi: Array
    b: Array
    d: Array
    n_modes: int
    truncated: bool
    _family: ModelFamily

    def __repr__(self) -> str:
        from ..display import modal_form_text

        return modal_form_text(self)

    def gyroscopic(self, thrust: float) -> Array:
        """Modal gyroscopic matrix ``Phi^T G(P) Phi`` (propeller speed may follow the thrust)."""
        _, _, g, _ = self._family.matrices(np.array([thrust]))
        return self.phi.T @ g[0] @ self.phi

    def matrices(self, thrust: float) -> tuple[Array, Array, Array]:
        """``(I, d + g, omega0^2 - P b)`` of the modal equations at thrust P (N)."""
        k = self.n_modes
        return np.eye(k), self.d + self.gyroscopic(thrust), np.diag(self.omega0**2) - thrust * self.b

    def eigenvalues(self, thrust: float) -> NDArray[np.complex128]:
        """Roots of ``det(lambda^2 I + lambda (d + g) + omega0^2 - P b) = 0`` (1/s)."""
        m, c, k = self.matrices(thrust)
        return np.linalg.eigvals(state_matrices(m, c, k))


def modal_form(model: Model, n_modes: int | None = None, *, modal_damping: bool = False) -> ModalForm:
    """Build the paper's modal form of ``model`` (classical linearization).

    Parameters
    ----------
    n_modes : int, optional
        Keep the ``n_modes`` lowest modes (default all six: exact).
    modal_damping : bool
        Keep only the diagonal of ``Phi^T D Phi`` (the paper's assumption); otherwise the full
        modal damping matrix.
    """
    n = 6 if n_modes is None else int(n_modes)
    if not 1 <= n <= 6:
        raise ModelError("n_modes", n_modes, "must be between 1 and 6")
    fam = ModelFamily(model, "classical", mount_dofs=False)  # the rigid-body modal form: mounts as their static 6 x 6
    m, d, _, k = fam.matrices(np.array([0.0, 1.0]))
    k_c, k_g = k[0], -(k[1] - k[0])
    w2, phi = sla.eigh(0.5 * (k_c + k_c.T), m[0])
    phi = phi[:, :n]
    dm = phi.T @ d[0] @ phi
    if modal_damping:
        dm = np.diag(np.diag(dm))
    return ModalForm(np.sqrt(w2[:n]), phi, phi.T @ k_g @ phi, dm, n, n < 6, fam)
