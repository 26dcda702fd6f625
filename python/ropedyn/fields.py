"""Fields of a run (definitions in docs/guide/visualization.md): the supports and the ground,
element velocity and speed, element angles, curvature at the joints, and the axial force.

Everything comes from the run file alone (a `ropedyn.io.Run`): the polyline, the state, the
element lengths, the effective scene text, and the internal forces and support anchors the
model stored with each record. No force law is evaluated here: the axial force is the
model's own (/forces/axial); a file written before the forces were stored has none.
"""
import dataclasses

import numpy as np


# --- supports -----------------------------------------------------------------------------

@dataclasses.dataclass
class Support:
    """One end support: kind ('pinned', 'clamped', 'free'), anchor (x, y) m at the first
    record, clamp angle; path (T, 2) m: the anchor at every record (/supports/*/position;
    None for a file without it), moving: whether it moves."""

    kind: str
    anchor: np.ndarray
    angle: float  # rad, from x towards y
    path: np.ndarray = None

    @property
    def moving(self):
        return self.path is not None and bool(np.any(np.ptp(self.path, axis=0) > 0.0))


def _vector(value, fallback):
    try:
        v = np.asarray(value, dtype=float).reshape(2)
    except (TypeError, ValueError):
        return fallback
    return fallback if not np.all(np.isfinite(v)) else v


def supports(run):
    """(top, bottom) supports: their kinds and clamp angles from the scene, their anchors
    from the file (/supports/*/position, where the model put them at each record). A file
    without those: the scene's anchors (the bottom's default: the rope's lower end at the
    start, as in the models), no path."""
    sup = run.group("supports")
    out = []
    for end, point in (("top", 0), ("bottom", -1)):
        kind = str(sup.get(end, "pinned" if end == "top" else "free")).lower()
        path = run.anchors.get(end)
        if path is not None and path.shape[0] > 0 and np.all(np.isfinite(path[0])):
            anchor = path[0].copy()
        else:
            path = None
            anchor = _vector(sup.get(f"{end}_anchor"), run.points[0, point].copy())
        out.append(Support(kind, anchor, np.radians(float(sup.get(f"{end}_angle_deg", 0.0))),
                           path))
    return tuple(out)


def ground_plane(run):
    """(point, unit normal) of the scene's ground plane (x, y; the normal towards the free
    side), or None when the scene has no ground contact (&effects ground = .false.)."""
    if not bool(run.group("effects").get("ground", False)):
        return None
    ground = run.group("ground")
    point = _vector(ground.get("point"), np.array([1.0, 0.0]))
    normal = _vector(ground.get("normal"), np.array([-1.0, 0.0]))
    length = np.linalg.norm(normal)
    if not length > 0:
        return None
    return point, normal / length


def water_surface(run):
    """x of the free surface (m, x down: water where x > surface), or None when the scene
    has no water (&effects water = .false.)."""
    if not bool(run.group("effects").get("water", False)):
        return None
    value = run.group("fluid").get("surface", 0.0)
    return float(np.asarray(value, dtype=float).reshape(-1)[0])


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
    """The axial force N (tension > 0) at the joints, as the run stored it (/forces/axial).

    values (T, n+1) at joints 0 (top end) .. n (bottom end), at arc lengths s (n+1,) m along
    the unstretched rope; per_element (T, n): the mean of an element's two joints;
    per_point (T, 2n): A_i its upper joint, B_i its lower one; definition: what it is."""

    s: np.ndarray
    values: np.ndarray
    per_element: np.ndarray
    per_point: np.ndarray
    definition: str


#: What /forces/axial holds (docs/guide/visualization.md): the model's own value at each joint.
AXIAL_DEFINITION = ("the model's tension at the joints (/forces/axial); element value: "
                    "the mean of its two joints")

#: Why a file without /forces/axial has no axial force.
PREDATES_FORCES = ("axial force not shown: the file predates stored internal forces "
                   "(no /forces/axial); run the scene again with this version of ropedyn")


def joint_arc_length(run):
    """Arc length of joints 0 .. n from the top along the unstretched rope (n+1,) m."""
    return np.concatenate([[0.0], np.cumsum(run.element_length)])


def axial_force(run):
    """(AxialForce, "") from the file's /forces/axial, or (None, why): a file written before
    the internal forces were stored has none, and none is derived here."""
    axial = run.forces.get("axial")
    if axial is None:
        return None, PREDATES_FORCES
    return AxialForce(joint_arc_length(run), axial, joints_to_elements(axial),
                      joints_to_points(axial), AXIAL_DEFINITION), ""
