"""Models and an independent forced-response implementation for the response tests.

The reference route here shares nothing with ``impstab.response`` beyond the linearized matrices
``M, D, G, K`` and the static pose of :func:`impstab.linearize` (the input both are built on): the
mount maps use a closed-form ``J_l^{-1}`` and SciPy's rotation vector, the solve is one
``numpy.linalg.solve`` per frequency, the hull force is formed mount by mount.
"""

from __future__ import annotations

import copy

import numpy as np
from conftest import asymmetric_model_dict, ring_model_dict
from scipy.spatial.transform import Rotation

import impstab
from impstab.model import model_from_dict

DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")


def ring_damped(**over) -> dict:
    """Symmetric three-mount ring, cg at A, damped: surge is decoupled (an exact SDOF)."""
    d = ring_model_dict()
    d["mount_rings"][0].update(c_axial=150.0, c_shear=40.0)
    d.update(over)
    return d


def asym_full(tangency: float = 0.8, spin: float = 300.0, law: str = "sqrt-thrust") -> dict:
    """Asymmetric layout (tilted axes, a full 6x6 mount with rotational stiffness and damping, cg
    and thrust off the axis), dampers on every mount, a spinning propeller."""
    d = copy.deepcopy(asymmetric_model_dict())
    d["thrust"]["tangency"] = tangency
    for m in d["mounts"][:3]:
        m.update(c_axial=60.0, c_shear=15.0)
    d["mounts"][3]["damping"] = (np.diag([20.0, 8.0, 8.0, 0.5, 0.7, 0.6])).tolist()
    d["propeller"] = {"polar_inertia": 0.05, "speed": spin, "speed_law": law}
    return d


def model(d: dict):
    return model_from_dict(copy.deepcopy(d))


def skew(a):
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def jl_inverse(phi):
    """Closed-form inverse left Jacobian of SO(3) (Barfoot, State Estimation, eq. 7.77b)."""
    th = np.linalg.norm(phi)
    s = skew(phi)
    if th < 1e-8:
        return np.eye(3) - 0.5 * s + s @ s / 12.0
    return np.eye(3) - 0.5 * s + (1.0 / th**2 - (1.0 + np.cos(th)) / (2.0 * th * np.sin(th))) * s @ s


def body_end_maps(mdl, rotation):
    """``B_i = [[I, -S(R0 r_i)], [0, J_l^{-1}(log R0)]]`` per mount, independently."""
    phi = Rotation.from_matrix(rotation).as_rotvec()
    out = []
    for m in mdl.mounts:
        b = np.zeros((6, 6))
        b[:3, :3] = np.eye(3)
        b[:3, 3:] = -skew(rotation @ m.position)
        b[3:, 3:] = jl_inverse(phi)
        out.append(b)
    return out


def reference_response(mdl, freqs, load, thrust, linearization=None, hull_stiffness=None):
    """Per-frequency ``numpy.linalg.solve``: returns ``q (nf, 6)``, mount forces ``(nf, nm, 3)``,
    hull displacements ``(nf, nm, 3)``.

    ``hull_stiffness(f) -> S`` (N/m, complex, isotropic; the same at every mount) makes the hull
    compliant: the mount in series with the hull point, whose force ``F = S x`` and
    ``F = P k* (B q - P^T x)``; the hull-end displacements are unknowns of one 6 + 3 nm system.
    """
    lin = impstab.linearize(mdl, thrust, linearization)
    maps = body_end_maps(mdl, lin.rotation)
    nm = len(mdl.mounts)
    q_out = np.empty((len(freqs), 6), complex)
    f_out = np.empty((len(freqs), nm, 3), complex)
    x_out = np.zeros((len(freqs), nm, 3), complex)
    for n, f in enumerate(freqs):
        w = 2 * np.pi * f
        ks = [m.stiffness + 1j * w * m.damping for m in mdl.mounts]
        z_body = lin.K + 1j * w * (lin.D + lin.G) - w**2 * lin.M
        if hull_stiffness is None:
            q = np.linalg.solve(z_body, load)
            q_out[n] = q
            for i, (b, k) in enumerate(zip(maps, ks)):
                f_out[n, i] = (k @ b @ q)[:3]
            continue
        s = hull_stiffness(f)
        # unknowns (q, x_1..x_nm): body rows Z q - sum B^T k* P^T x = F; hull rows S x - P k*(B q - P^T x) = 0
        big = np.zeros((6 + 3 * nm, 6 + 3 * nm), complex)
        rhs = np.zeros(6 + 3 * nm, complex)
        big[:6, :6] = z_body
        rhs[:6] = load
        for i, (b, k) in enumerate(zip(maps, ks)):
            sl = slice(6 + 3 * i, 9 + 3 * i)
            big[:6, sl] = -(b.T @ k)[:, :3]
            big[sl, :6] = -(k @ b)[:3, :]
            big[sl, sl] = s * np.eye(3) + k[:3, :3]
        sol = np.linalg.solve(big, rhs)
        q_out[n] = sol[:6]
        for i in range(nm):
            x = sol[6 + 3 * i: 9 + 3 * i]
            x_out[n, i] = x
            f_out[n, i] = s * x
    return q_out, f_out, x_out
