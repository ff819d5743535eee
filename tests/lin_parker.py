"""Lin & Parker's translational-rotational planetary model, typed from the paper in NumPy (the independent
implementation the tests compare gearsym's derived model with).

J. Lin and R. G. Parker, Analytical characterization of the unique properties of planetary gear free vibration,
J. Vib. Acoust. 121 (1999) 316-321, Eqs. (1)-(5): coordinates q = (x_c, y_c, u_c, x_r, y_r, u_r, x_s, y_s, u_s,
xi_1, eta_1, u_1, ..., xi_N, eta_N, u_N), u = r theta; M = diag(M_c, M_r, M_s, M_1..M_N) with M_j = diag(m_j, m_j,
I_j/r_j^2); K = K_b + K_m with the bearing matrix K_b = diag(K_cb, K_rb, K_sb, 0...), K_jb = diag(k_j, k_j, k_ju),
and the mesh and planet-bearing blocks below (psi_sn = psi_n - alpha_s, psi_rn = psi_n + alpha_r). The gyroscopic
matrix G and the centripetal K_Omega are those of Eq. (1) (Omega_c G q' and -Omega_c^2 K_Omega q).
"""
from __future__ import annotations

import math

import numpy as np


def blocks(psi: float, alpha_s: float, alpha_r: float, k_p: float, k_sp: float, k_rp: float):
    """The planet's stiffness blocks K_c1..K_c3, K_r1..K_r3, K_s1..K_s3 of Lin & Parker's Eq. (5)."""
    s, c = math.sin, math.cos
    kc1 = k_p * np.array([[1, 0, -s(psi)], [0, 1, c(psi)], [-s(psi), c(psi), 1]])
    kc2 = -k_p * np.array([[c(psi), -s(psi), 0], [s(psi), c(psi), 0], [0, 1, 0]])
    kc3 = k_p * np.diag([1.0, 1.0, 0.0])
    pr = psi + alpha_r
    kr1 = k_rp * np.array([[s(pr) ** 2, -c(pr) * s(pr), -s(pr)], [-c(pr) * s(pr), c(pr) ** 2, c(pr)],
                           [-s(pr), c(pr), 1]])
    kr2 = k_rp * np.array([[-s(pr) * s(alpha_r), s(pr) * c(alpha_r), s(pr)],
                           [c(pr) * s(alpha_r), -c(pr) * c(alpha_r), -c(pr)],
                           [s(alpha_r), -c(alpha_r), -1]])
    kr3 = k_rp * np.array([[s(alpha_r) ** 2, -s(alpha_r) * c(alpha_r), -s(alpha_r)],
                           [-s(alpha_r) * c(alpha_r), c(alpha_r) ** 2, c(alpha_r)],
                           [-s(alpha_r), c(alpha_r), 1]])
    ps = psi - alpha_s
    ks1 = k_sp * np.array([[s(ps) ** 2, -c(ps) * s(ps), -s(ps)], [-c(ps) * s(ps), c(ps) ** 2, c(ps)],
                           [-s(ps), c(ps), 1]])
    ks2 = k_sp * np.array([[s(ps) * s(alpha_s), s(ps) * c(alpha_s), -s(ps)],
                           [-c(ps) * s(alpha_s), -c(ps) * c(alpha_s), c(ps)],
                           [-s(alpha_s), -c(alpha_s), 1]])
    ks3 = k_sp * np.array([[s(alpha_s) ** 2, s(alpha_s) * c(alpha_s), -s(alpha_s)],
                           [s(alpha_s) * c(alpha_s), c(alpha_s) ** 2, -c(alpha_s)],
                           [-s(alpha_s), -c(alpha_s), 1]])
    return (kc1, kc2, kc3), (kr1, kr2, kr3), (ks1, ks2, ks3)


def matrices(p: dict, planets: int):
    """M, K, G and K_Omega of Lin & Parker's model (``p``: masses m_*, I/r^2 as j_*, stiffnesses k_*, alpha_s,
    alpha_r in radians), for ``planets`` equally spaced planets."""
    n = 3 * (planets + 3)
    mass = np.zeros((n, n))
    for j, name in enumerate("crs"):
        mass[3 * j:3 * j + 3, 3 * j:3 * j + 3] = np.diag([p[f"m_{name}"], p[f"m_{name}"], p[f"j_{name}"]])
    for i in range(planets):
        k = 9 + 3 * i
        mass[k:k + 3, k:k + 3] = np.diag([p["m_p"], p["m_p"], p["j_p"]])
    stiffness = np.zeros((n, n))
    for j, name in enumerate("crs"):
        stiffness[3 * j:3 * j + 3, 3 * j:3 * j + 3] += np.diag([p[f"k_{name}"], p[f"k_{name}"], p[f"k_{name}u"]])
    for i in range(planets):
        psi = 2 * math.pi * i / planets
        (kc1, kc2, kc3), (kr1, kr2, kr3), (ks1, ks2, ks3) = blocks(psi, p["alpha_s"], p["alpha_r"], p["k_p"],
                                                                   p["k_sp"], p["k_rp"])
        k = 9 + 3 * i
        for j, (b1, b2) in enumerate(((kc1, kc2), (kr1, kr2), (ks1, ks2))):
            stiffness[3 * j:3 * j + 3, 3 * j:3 * j + 3] += b1
            stiffness[3 * j:3 * j + 3, k:k + 3] += b2
            stiffness[k:k + 3, 3 * j:3 * j + 3] += b2.T
        stiffness[k:k + 3, k:k + 3] += kc3 + kr3 + ks3
    gyroscopic = np.zeros((n, n))
    centripetal = np.zeros((n, n))
    for j in range(planets + 3):
        m = mass[3 * j, 3 * j]
        gyroscopic[3 * j:3 * j + 2, 3 * j:3 * j + 2] = np.array([[0.0, -2 * m], [2 * m, 0.0]])
        centripetal[3 * j:3 * j + 2, 3 * j:3 * j + 2] = np.diag([m, m])
    return mass, stiffness, gyroscopic, centripetal


def natural_frequencies(mass: np.ndarray, stiffness: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies (Hz, ascending) and mass-normalised shapes of K phi = w^2 M phi (M is diagonal)."""
    scale = 1 / np.sqrt(np.diag(mass))
    w2, y = np.linalg.eigh(scale[:, None] * stiffness * scale[None, :])
    return np.sqrt(np.clip(w2, 0, None)) / (2 * math.pi), scale[:, None] * y
