"""Read a ropedyn HDF5 run and derive what the pictures show (shared by animate.py,
plot_run.py, write_xdmf.py and readme_figures.py).

Everything is computed from the run file alone (docs/output.md): the polyline, the state,
the element lengths and the effective scene text stored in the root attribute `scene`.
The definitions of the derived fields (axial force, curvature, speed) are in
docs/visualization.md.
"""
import dataclasses
import re

import h5py
import numpy as np

ENERGY_NAMES = ("kinetic", "elastic", "gravity", "dissipated", "support_work", "total")


def text(value):
    """An HDF5 string attribute as str (h5py returns fixed-length strings as bytes)."""
    if isinstance(value, (bytes, np.bytes_)):
        return value.decode()
    return str(value)


# --- the scene text (namelist) -------------------------------------------------------------

def _strip_comment(line):
    """The line without its '!' comment ('!' inside quotes is kept)."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "!":
            return line[:i]
    return line


def _mask_quotes(body):
    """body with the characters inside quotes replaced by '_' (same length)."""
    out, quote = [], None
    for ch in body:
        if quote:
            out.append(ch if ch == quote else "_")
            if ch == quote:
                quote = None
        else:
            if ch in "'\"":
                quote = ch
            out.append(ch)
    return "".join(out)


def _split_commas(value):
    """Split a value at commas outside quotes."""
    masked = _mask_quotes(value)
    parts, start = [], 0
    for i, ch in enumerate(masked):
        if ch == ",":
            parts.append(value[start:i])
            start = i + 1
    parts.append(value[start:])
    return [p.strip() for p in parts if p.strip()]


def _parse_token(token):
    """One namelist value: quoted string, logical, integer or real (NaN allowed)."""
    if token[:1] in "'\"" and token[-1:] == token[:1] and len(token) >= 2:
        return token[1:-1]
    low = token.lower()
    if low in (".true.", "t", ".t."):
        return True
    if low in (".false.", "f", ".f."):
        return False
    try:
        return int(token)
    except ValueError:
        pass
    try:
        return float(low.replace("d", "e"))
    except ValueError:
        return token


def parse_namelist(scene_text):
    """Namelist text -> {group: {key: value}} (lower-case names; 2-vectors as lists).

    Handles the echo written into every run (one key a line) and hand-written files (several
    keys a line, `key(i) = value` components, comments)."""
    body = "\n".join(_strip_comment(line) for line in scene_text.splitlines())
    masked = _mask_quotes(body)
    groups = {}
    for match in re.finditer(r"&(\w+)(.*?)(?:/|&end\b)", masked, re.S | re.I):
        name = match.group(1).lower()
        start, end = match.span(2)
        content, content_masked = body[start:end], masked[start:end]
        keys = list(re.finditer(r"(\w+)\s*(?:\(\s*(\d+)\s*\))?\s*=", content_masked))
        values = groups.setdefault(name, {})
        for k, key in enumerate(keys):
            stop = keys[k + 1].start() if k + 1 < len(keys) else len(content)
            tokens = [_parse_token(t) for t in _split_commas(content[key.end():stop])]
            if not tokens:
                continue
            key_name = key.group(1).lower()
            if key.group(2):
                vector = list(values.get(key_name, [float("nan")] * 2))
                vector[int(key.group(2)) - 1] = tokens[0]
                values[key_name] = vector
            else:
                values[key_name] = tokens[0] if len(tokens) == 1 else tokens
    return groups


# --- the run ------------------------------------------------------------------------------

@dataclasses.dataclass
class Run:
    """One ropedyn output file, read into memory (records: len(/time))."""

    path: str
    time: np.ndarray            # (T,) s
    points: np.ndarray          # (T, 2n, 2) m: A_1, B_1, A_2, ... (x down, y horizontal)
    q: np.ndarray               # (T, n, 3) element centre x, y (m), angle phi (rad)
    qdot: np.ndarray            # (T, n, 3)
    element_length: np.ndarray  # (n,) m
    element_mass: np.ndarray    # (n,) kg
    energy: dict                # name -> (T,) J
    step_size: np.ndarray       # (T,) s
    order: np.ndarray           # (T,)
    model: str
    method: str
    status: str
    scene: dict                 # parse_namelist of the scene attribute

    @property
    def n(self):
        """Number of elements (members)."""
        return self.q.shape[1]

    def group(self, name):
        """A scene group as a dict ({} when absent)."""
        return self.scene.get(name, {})


def load_run(path):
    """Read a run file; records beyond len(/time) (a half-written record) are dropped."""
    with h5py.File(path, "r") as f:
        records = f["time"].shape[0]

        def series(name):
            return f[name][:records] if name in f else None

        energy = {k: series(f"energy/{k}") for k in ENERGY_NAMES if f"energy/{k}" in f}
        return Run(path=str(path), time=f["time"][:], points=series("rope/points"),
                   q=series("state/q"), qdot=series("state/qdot"),
                   element_length=f["rope/element_length"][:],
                   element_mass=f["rope/element_mass"][:], energy=energy,
                   step_size=series("solver/step_size"), order=series("solver/order"),
                   model=text(f.attrs.get("model", "unknown")).strip().lower(),
                   method=text(f.attrs.get("method", "")).strip(),
                   status=text(f.attrs.get("status", "")).strip(),
                   scene=parse_namelist(text(f.attrs.get("scene", ""))))


def title(run):
    """A one-line description: model, n, method, status."""
    return f"{run.model.upper()}, n = {run.n}, {run.method} ({run.status})"


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
    d_s = mpp_axial_damping_factor * eta A/l (docs/physics-mpp.md).

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


# --- drawing helpers (matplotlib axes in the picture frame: y right, x down) --------------

def draw_supports(ax, run, size=None, color="0.25"):
    """Draw the anchors of pinned and clamped ends (hatched ceiling / wall) on ax,
    which shows (y, x) with x downward."""
    size = size or 0.06 * float(run.group("rope").get("length", run.element_length.sum()))
    for sup, sign in zip(supports(run), (-1.0, 1.0)):
        if sup.kind not in ("pinned", "clamped"):
            continue
        x0, y0 = sup.anchor
        if sup.kind == "pinned":
            # a ceiling (or floor) segment with hatching, and the pin
            ax.plot([y0 - size, y0 + size], [x0 + sign * 0.3 * size] * 2, color=color, lw=1.5)
            for k in np.linspace(-size, size, 6):
                ax.plot([y0 + k, y0 + k + 0.3 * size],
                        [x0 + sign * 0.3 * size, x0 + sign * 0.6 * size], color=color, lw=0.8)
            ax.plot([y0], [x0], "o", ms=5, mfc="white", mec=color, mew=1.5, zorder=5)
        else:
            # a wall perpendicular to the clamp direction
            direction = np.array([np.cos(sup.angle), np.sin(sup.angle)]) * -sign
            normal = np.array([-direction[1], direction[0]])
            ends = [sup.anchor - size * normal, sup.anchor + size * normal]
            ax.plot([ends[0][1], ends[1][1]], [ends[0][0], ends[1][0]], color=color, lw=2.5)
            for k in np.linspace(-size, size, 6):
                p = sup.anchor + k * normal
                q = p - 0.3 * size * direction + 0.3 * size * normal
                ax.plot([p[1], q[1]], [p[0], q[0]], color=color, lw=0.8)


def picture_limits(run, margin=0.08):
    """((ymin, ymax), (xmin, xmax)) covering every record and the anchors, with a margin."""
    pts = run.points.reshape(-1, 2)
    anchors = np.array([s.anchor for s in supports(run) if s.kind != "free"]).reshape(-1, 2)
    allp = np.vstack([pts, anchors]) if anchors.size else pts
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    pad = margin * max(hi - lo) + 1e-9
    return (lo[1] - pad, hi[1] + pad), (lo[0] - pad, hi[0] + pad)


def setup_picture_axes(ax, run):
    """Axes showing y to the right and x downward, limits covering the whole run (call
    fit_equal after the layout is final to make the scales equal)."""
    (ymin, ymax), (xmin, xmax) = picture_limits(run)
    ax.set_xlim(ymin, ymax)
    ax.set_ylim(xmax, xmin)  # x points down
    ax.set_xlabel("y (m)")
    ax.set_ylabel("x (m, down)")
    ax.grid(alpha=0.25)


def fit_equal(ax):
    """Widen the x or y limits so that one metre is as long across as down (the axes box
    stays as laid out, so the picture fills it)."""
    box = ax.get_window_extent()
    (y0, y1), (x1, x0) = ax.get_xlim(), ax.get_ylim()
    want = box.width / max(box.height, 1.0)
    across, down = y1 - y0, x1 - x0
    if across / down < want:
        pad = (want * down - across) / 2.0
        ax.set_xlim(y0 - pad, y1 + pad)
    else:
        pad = (across / want - down) / 2.0
        ax.set_ylim(x1 + pad, x0 - pad)
    ax.set_aspect("equal", adjustable="box")


def parse_size(value):
    """'WxH' -> (W, H) pixels."""
    match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", value)
    if not match:
        raise ValueError(f"size '{value}': expected WIDTHxHEIGHT in pixels, e.g. 640x480")
    return int(match.group(1)), int(match.group(2))
