# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The seed paper's own formulation, transcribed as written, to measure its error.

Not for use anywhere else: its position constraint (Eq. 2, sin α = 1 − cos β) is not a
consequence of rigid links, and its variable-law accelerations take ω̇ = 4.4 rad/s² from
α(t) = 1.9·t (Eqs. 6a–6c) and carry an ω̇² term (Eq. 19). Notation as in the paper:
l, m = sin α, cos α; n, o = sin β, cos β; p, q = sin γ, cos γ. It is defined for the paper's
mechanism (OA = BC) and its two drive laws only; outside α ∈ [0°, 90°] Eq. (2) has no solution
when 1 − sin α > 1, and the functions return NaN there.
"""

from __future__ import annotations

import math

from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import FourBar

# Eq. (6c): the paper's constant angular acceleration of the disk under the variable law.
SEED_VARIABLE_OMEGA_DOT = 2.3 * 1.9


def seed_state(linkage: FourBar, alpha: float, drive: DriveLaw) -> dict[str, float]:
    """β, γ and the bars' rates and accelerations by the paper's Eqs. (2)–(19)."""
    oa = linkage.crank_length
    ab = linkage.coupler_length
    bc = linkage.rocker_length
    oc = linkage.ground_x
    l, m = math.sin(alpha), math.cos(alpha)
    cos_beta = 1.0 - l  # Eq. (2)
    if abs(cos_beta) > 1.0:
        nan = math.nan
        return {'beta': nan, 'gamma': nan, 'omega_ab': nan, 'omega_bc': nan,
                'omega_dot_ab': nan, 'omega_dot_bc': nan}
    beta = math.acos(cos_beta)
    n, o = math.sin(beta), cos_beta
    # Eqs. (3) and (4): opposite and adjacent sides of the right triangle on AB.
    gamma = math.atan2(bc * n + oa * m, oc - oa * l - bc * o)
    p, q = math.sin(gamma), math.cos(gamma)
    omega = drive.omega0 + drive.k * alpha
    v_a = oa * omega
    v_b = v_a * (m * q + l * p) / (n * q + o * p)  # Eq. (9)
    omega_ab = v_a / ab * (m * o - l * n) / (o * p + n * q)  # Eq. (10)
    omega_bc = -v_b / bc  # Eqs. (7) and (8b)
    if drive.k == 0.0:
        # Eqs. (15) and (16), constant ω.
        ab1 = omega**2 * oa * (l * o + m * n)
        ab2 = omega_bc**2 * bc * (o**2 + n**2)
        ab3 = omega_ab**2 * ab * (o * q - n * p)
        ab4 = ab * (o * p + n * q)
        omega_dot_ab = -(ab1 + ab2 + ab3) / ab4
        bc1 = omega**2 * oa * (m * p - l * q)
        bc2 = omega_ab**2 * ab * (p**2 + q**2)
        bc3 = omega_bc**2 * bc * (n * p - o * q)
        bc4 = bc * (n * q + o * p)
        omega_dot_bc = -(bc1 - bc2 + bc3) / bc4
    else:
        # Eqs. (18) and (19), variable ω, with the paper's ω̇ of Eq. (6c).
        omega_dot = SEED_VARIABLE_OMEGA_DOT
        ab1 = omega**2 * oa * (l * o + m * n)
        ab2 = omega_dot * oa * (m * o - l * n)
        ab3 = omega_bc**2 * bc * (o**2 + n**2)
        ab4 = omega_ab**2 * ab * (o * q - n * p)
        ab5 = ab * (o * p + n * q)
        omega_dot_ab = (-ab1 + ab2 - ab3 - ab4) / ab5
        bc1 = omega**2 * oa * (m * p - l * q)
        bc2 = omega_dot**2 * oa * (m * q + l * p)
        bc3 = omega_bc**2 * bc * (n * p - o * q)
        bc4 = omega_ab**2 * ab * (p**2 + q**2)
        bc5 = bc * (n * q + o * p)
        omega_dot_bc = (-bc1 - bc2 - bc3 + bc4) / bc5
    return {'beta': beta, 'gamma': gamma, 'omega_ab': omega_ab, 'omega_bc': omega_bc,
            'omega_dot_ab': omega_dot_ab, 'omega_dot_bc': omega_dot_bc}
