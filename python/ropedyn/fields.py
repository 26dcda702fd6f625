"""Derived fields of a run (definitions in docs/guide/visualization.md): the supports, element
velocity and speed, element angles, curvature at the joints and the axial force.

Everything is computed from the run file alone (a `ropedyn.io.Run`): the polyline, the
state, the element lengths and the effective scene text.
"""
import dataclasses

import numpy as np


# --- supports -----------------------------------------------------------------------------

@dataclasses.dataclass
class Support:
    """One end support: kind ('pinned', 'clamped', 'free'), anchor (x, y) m, clamp angle."""

    kind: str
    anchor: np.ndarray
    angle: float  # rad, from x towards y


def _vector(value, fallback):
    try:
        v = np.asarray(value, dtype=float).reshape(2)
    except (TypeError, ValueError):
        return fallback
    return fallback if not np.all(np.isfinite(v)) else v


def supports(run):
    """(top, bottom) supports from the scene. The bottom anchor defaults to the rope's lower
    end in its initial state, as in the models."""
    sup = run.group("supports")
    top_kind = str(sup.get("top", "pinned")).lower()
    bottom_kind = str(sup.get("bottom", "free")).lower()
    top = Support(top_kind, _vector(sup.get("top_anchor"), run.points[0, 0].copy()),
                  np.radians(float(sup.get("top_angle_deg", 0.0))))
    bottom = Support(bottom_kind, _vector(sup.get("bottom_anchor"), run.points[0, -1].copy()),
                     np.radians(float(sup.get("bottom_angle_deg", 0.0))))
    return top, bottom


# --- derived fields -----------------------------------------------------------------------

def velocity(run):
    """Element centre velocity (T, n, 2) m/s, from /state/qdot."""
    return run.qdot[:, :, :2]


def speed(run):
    """Element centre speed |(xdot, ydot)| (T, n) m/s."""
    return np.linalg.norm(velocity(run), axis=-1)


def element_angles(run):
    """Element direction angle (T, n) rad from x towards y, from the polyline A_i -> B_i
    (equal to phi for RFEM; the member direction for MPP)."""
    d = run.points[:, 1::2] - run.points[:, 0::2]
    return np.arctan2(d[..., 1], d[..., 0])


def _wrap(angle):
    return (angle + np.pi) % (2.0 * np.pi) - np.pi


def joint_spacing(run):
    """Rope length per joint (n+1,) m, for joints 0 (top) .. n (bottom).

    RFEM: the primary division dl = L/(n-1) at every joint (its bending spring is EI/dl);
    other models: the mean length of the two members at the joint (end joints: the end
    member's length)."""
    length = run.element_length
    if run.model == "rfem":
        return np.full(run.n + 1, length.sum() / (run.n - 1))
    inner = 0.5 * (length[:-1] + length[1:])
    return np.concatenate([[length[0]], inner, [length[-1]]])


def joint_curvature(run):
    """Curvature at the joints (T, n+1) 1/m: joint 0 is the top support, joint n the bottom.

    Inner joint j: wrap(phi_{j+1} - phi_j)/h_j. A clamped end: the angle between the end
    element and the clamp angle over h; a pinned or free end carries no moment: 0."""
    phi = element_angles(run)
    h = joint_spacing(run)
    kappa = np.zeros((phi.shape[0], run.n + 1))
    kappa[:, 1:-1] = _wrap(np.diff(phi, axis=1)) / h[1:-1]
    top, bottom = supports(run)
    if top.kind == "clamped":
        kappa[:, 0] = _wrap(phi[:, 0] - top.angle) / h[0]
    if bottom.kind == "clamped":
        kappa[:, -1] = _wrap(bottom.angle - phi[:, -1]) / h[-1]
    return kappa


def joints_to_elements(joint_values):
    """Element values (T, n) as the mean of the two joints at the element's ends."""
    return 0.5 * (joint_values[:, :-1] + joint_values[:, 1:])


def joints_to_points(joint_values):
    """Point values (T, 2n): A_i takes joint i-1|i (its upper joint), B_i joint i|i+1."""
    out = np.empty((joint_values.shape[0], 2 * (joint_values.shape[1] - 1)))
    out[:, 0::2] = joint_values[:, :-1]
    out[:, 1::2] = joint_values[:, 1:]
    return out


@dataclasses.dataclass
class AxialForce:
    """The axial force N (tension > 0) at positions s along the unstretched rope.

    values (T, m) at arc lengths s (m,); per_element (T, n); per_point (T, 2n);
    definition: one line saying what was computed."""

    s: np.ndarray
    values: np.ndarray
    per_element: np.ndarray
    per_point: np.ndarray
    definition: str


def _rope_constants(run):
    rope = run.group("rope")
    effects = run.group("effects")
    area = np.pi * float(rope.get("diameter", 0.005)) ** 2 / 4.0
    young = float(rope.get("young_modulus", 35e6))
    eta = float(rope.get("normal_damping", 1e3))
    factor = float(run.group("supports").get("support_stiffness_factor", 1.0))
    return (area, young, eta, factor, bool(effects.get("tension", True)),
            bool(effects.get("damping", True)))


def _rfem_axial_force(run):
    """RFEM: spring + damper of the axial SDEs, exactly as src/ropedyn_rfem.f90 forms them."""
    area, young, eta, factor, tension_on, damping_on = _rope_constants(run)
    dl = run.element_length.sum() / (run.n - 1)
    cx, bx = young * area / dl, (eta * area / dl if damping_on else 0.0)
    phi, w = run.q[..., 2], run.qdot[..., 2]
    e = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    nrm = np.stack([-np.sin(phi), np.cos(phi)], axis=-1)
    v = velocity(run)
    half = run.element_length / 2.0
    a_pts, b_pts = run.points[:, 0::2], run.points[:, 1::2]
    force = np.zeros((run.time.size, run.n + 1))
    if tension_on:
        d = a_pts[:, 1:] - b_pts[:, :-1]                       # A_{j+1} - B_j
        ea, na, nb = e[:, :-1], nrm[:, :-1], nrm[:, 1:]
        s = np.sum(ea * d, axis=-1)
        s_dot = (np.sum(ea * (v[:, 1:] - v[:, :-1]), axis=-1)
                 + np.sum(na * d, axis=-1) * w[:, :-1]
                 - half[1:] * np.sum(ea * nb, axis=-1) * w[:, 1:])
        force[:, 1:-1] = cx * s + bx * s_dot
    top, bottom = supports(run)
    if top.kind in ("pinned", "clamped"):
        d = a_pts[:, 0] - top.anchor
        d_dot = v[:, 0] - half[0] * w[:, 0, None] * nrm[:, 0]
        force[:, 0] = factor * (cx * np.sum(e[:, 0] * d, axis=-1)
                                + bx * np.sum(e[:, 0] * d_dot, axis=-1))
    if bottom.kind in ("pinned", "clamped"):
        d = bottom.anchor - b_pts[:, -1]
        d_dot = -(v[:, -1] + half[-1] * w[:, -1, None] * nrm[:, -1])
        force[:, -1] = factor * (cx * np.sum(e[:, -1] * d, axis=-1)
                                 + bx * np.sum(e[:, -1] * d_dot, axis=-1))
    s_joint = np.concatenate([[0.0], np.cumsum(run.element_length)])
    damper = "spring + damper" if bx > 0 else "spring (no damping)"
    return AxialForce(s_joint, force, joints_to_elements(force), joints_to_points(force),
                      f"RFEM axial SDEs ({damper}) at the joints and supports; "
                      "element value = mean of its two joints")


def _member_axial_force(run):
    """MPP: the force in each member's spring and damper, k_s u + d_s u', k_s = E A/l,
    d_s = mpp_axial_damping_factor * eta A/l (docs/theory/mpp.md).

    u_i = |B_i - A_i| - l (member i is drawn from joint P_{i-1} to joint P_i). Its rate comes
    from the chain of joint velocities, P_0 fixed at the top anchor:
    u_i' = e_i . (C_i' - P_{i-1}'), P_i' = P_{i-1}' + u_i' e_i + (l + u_i) phi_i' n_i."""
    area, young, eta, _, tension_on, damping_on = _rope_constants(run)
    if not tension_on:
        return None, ("axial force skipped: inextensible members (&effects tension = "
                      ".false.): the axial force is a constraint force the output does not hold")
    length = run.element_length
    chord = run.points[:, 1::2] - run.points[:, 0::2]
    member = np.linalg.norm(chord, axis=-1)
    if not (np.all(np.isfinite(member)) and np.all(length > 0) and np.all(member > 0)):
        return None, "axial force skipped: the polyline does not give the member lengths"
    stretch = member - length
    force = young * area * stretch / length
    top, _ = supports(run)
    factor = float(run.group("model").get("mpp_axial_damping_factor", 1.0))
    damper = damping_on and eta * factor > 0
    if damper and top.kind == "free":
        damper = False  # the MPP needs a fixed top joint; should not happen
    if damper:
        e = chord / member[..., None]
        nrm = np.stack([-e[..., 1], e[..., 0]], axis=-1)
        v, w = velocity(run), run.qdot[..., 2]
        joint_v = np.zeros_like(v[:, 0])
        rate = np.empty_like(stretch)
        for i in range(run.n):
            rate[:, i] = np.sum(e[:, i] * (v[:, i] - joint_v), axis=-1)
            joint_v = (joint_v + rate[:, i, None] * e[:, i]
                       + (length[i] + stretch[:, i])[:, None] * w[:, i, None] * nrm[:, i])
        force = force + factor * eta * area / length * rate
    s_mid = np.cumsum(length) - length / 2.0
    parts = "spring + damper" if damper else "spring (no damping)"
    return AxialForce(s_mid, force, force, np.repeat(force, 2, axis=1),
                      f"{run.model.upper()} member {parts}, stretch u = polyline member "
                      "length - element_length; one value per member"), ""


def axial_force(run):
    """(AxialForce, message): the force along the rope, or (None, why it was skipped)."""
    if run.model == "rfem":
        return _rfem_axial_force(run), ""
    if run.model == "mpp":
        return _member_axial_force(run)
    return None, f"axial force skipped: unknown model '{run.model}'"

