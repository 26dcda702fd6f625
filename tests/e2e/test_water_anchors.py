"""A line in water against physics that test_water.py does not cover: a mooring line with
its lower part on the seabed (the elastic catenary with touchdown, submerged weight), a line
lighter than water between two pins (the catenary upside down), the seabed's friction on
the submerged weight, a line falling end first (tangential drag and tangential added
mass), the tangential added mass in the axial modes, a line heaved through the surface (its added mass's change), and
no drag above the surface."""
from math import pi, sqrt

import h5py
import numpy as np
import pytest

G, RHO = 9.81, 1000.0


def area(d):
    return pi * d * d / 4


def bisect(f, lo, hi):
    flo = f(lo)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if (f(mid) > 0) == (flo > 0):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def touchdown_catenary(length, span, depth, w, ea):
    """H and V at the fairlead of an elastic line of unstretched length L, weight w per
    unstretched metre, its lower part lying on a frictionless seabed `depth` below the
    fairlead and `span` from its anchor (Jonkman's closed form, no seabed friction):
    span = L - V/w + (H/w) asinh(V/H) + H L/EA, depth = (H/w)(sqrt(1 + (V/H)^2) - 1)
    + V^2/(2 EA w)."""
    def v_of(h):
        return bisect(lambda v: h / w * (sqrt(1 + (v / h) ** 2) - 1) + v * v / (2 * ea * w)
                      - depth, 0.0, 10 * (w * length + h))

    def span_error(h):
        v = v_of(h)
        return length - v / w + h / w * np.arcsinh(v / h) + h * length / ea - span

    h = bisect(span_error, 1e-9 * w * length, 1e3 * w * length)
    return h, v_of(h)


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_a_mooring_line_with_touchdown_in_water(run, tmp_path, kind):
    """50 m of line (1 kg/m, d = 2 cm, EA 1e5 N) from a fairlead 20 m above the seabed to an
    anchor on it 40 m away, wholly under water: H, V and the top tension of the elastic
    catenary with touchdown and the submerged weight, to 5e-4 at n = 100 (measured 8e-5 to
    2.7e-4), the grounded part's tension H (no friction at rest), the touchdown point within
    an element, and the seabed's sink w'/k (the median of the points on it)."""
    length, depth, span, mu, d, ea, k = 50.0, 20.0, 40.0, 1.0, 0.02, 1.0e5, 1.0e6
    w = (mu - RHO * area(d)) * G
    h, v = touchdown_catenary(length, span, depth, w, ea)
    grounded = (length - v / w) * (1 + h / ea)
    (tmp_path / "moor.nml").write_text(f"""
&rope length = {length}, mass_per_length = {mu}, axial_stiffness = {ea}, diameter = {d} /
&model kind = '{kind}', elements = 100 /
&supports top = 'pinned', bottom = 'pinned', bottom_anchor = {depth}, {span},
          end_compliance = 'split' /
&initial shape = 'equilibrium', angle_deg = 70.0 /
&effects water = .true., ground = .true. /
&fluid density = {RHO}, surface = -1.0 /
&ground point = {depth}, 0.0, normal = -1.0, 0.0, stiffness = {k}, friction_coefficient = 0.5 /
""")
    proc = run("statics", "moor.nml", "-o", "moor.h5")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "moor.h5") as f:
        top = f["supports/top/reaction"][0]
        axial = f["forces/axial"][0]
        points = f["rope/points"][0]
    assert abs(-top[0] / v - 1) < 5e-4, (top, v)
    assert abs(-top[1] / h - 1) < 5e-4, (top, h)
    assert abs(np.hypot(*top) / np.hypot(h, v) - 1) < 5e-4
    assert abs(axial[-1] / h - 1) < 5e-4, (axial[-1], h)
    on_ground = np.nonzero(points[:, 0] > depth)[0]
    assert abs(points[on_ground[0], 1] - (span - grounded)) < length / 99
    assert abs(np.median(points[on_ground, 0]) - depth - w / k) < 0.01 * w / k


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_a_line_lighter_than_water_hangs_upward(run, tmp_path, kind):
    """10 m of line half as dense as water between pins 8 m apart, started hanging down:
    the statics find the catenary of the net buoyancy upside down (rise, H and the end
    tension of the elastic catenary, to 1e-4 at n = 100; measured 5e-5)."""
    length, span, d, ea = 10.0, 8.0, 0.02, 2.0e3
    mu = 0.5 * RHO * area(d)
    w = (RHO * area(d) - mu) * G
    v = w * length / 2

    def span_of(h):
        return h * length / ea + h / w * (np.arcsinh(v / h) - np.arcsinh((v - w * length) / h))

    h = bisect(lambda h: span_of(h) - span, 1e-6, 1e6)
    rise = (sqrt(h * h + v * v) - h) / w + w * length ** 2 / (8 * ea)
    (tmp_path / "light.nml").write_text(f"""
&rope length = {length}, mass_per_length = {mu!r}, axial_stiffness = {ea}, diameter = {d} /
&model kind = '{kind}', elements = 100 /
&supports top = 'pinned', bottom = 'pinned', top_anchor = 10.0, 0.0,
          bottom_anchor = 10.0, {span}, support_stiffness_factor = 1000.0 /
&initial shape = 'hanging' /
&effects water = .true. /
&fluid density = {RHO}, surface = -20.0 /
""")
    proc = run("statics", "light.nml", "-o", "light.h5")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "light.h5") as f:
        points = f["rope/points"][0]
        top = f["supports/top/reaction"][0]
    assert points[:, 0].max() < 10.0 + 1e-6                  # nothing below the anchors
    assert abs((10.0 - points[:, 0].min()) / rise - 1) < 1e-4
    assert top[0] > 0                                        # the pin holds the line down
    assert abs(abs(top[1]) / h - 1) < 1e-4
    assert abs(np.hypot(*top) / sqrt(h * h + v * v) - 1) < 1e-4


def test_the_seabed_friction_takes_the_submerged_weight(run, tmp_path):
    """A line lying on the seabed, dragged along its axis by a current through linear
    tangential drag c_t: it slides at u - mu_f w'/c_t, w' the weight less the buoyancy
    (the dry weight would give 0.5095 m/s instead of 0.6636), and sinks w'/k into it."""
    mu, d, ct, u, mu_f, k = 1.0, 0.02, 10.0, 1.0, 0.5, 1.0e6
    w = (mu - RHO * area(d)) * G
    (tmp_path / "slide.nml").write_text(f"""
&rope length = 5.0, mass_per_length = {mu}, axial_stiffness = 1.0e5, bending_stiffness = 1.0,
      axial_damping = 10.0, diameter = {d} /
&model kind = 'rfem', elements = 10 /
&supports top = 'free', bottom = 'free', top_anchor = 20.0, 0.0 /
&initial shape = 'straight', angle_deg = 90.0 /
&effects water = .true., drag = .true., ground = .true. /
&fluid density = {RHO}, surface = 0.0, normal_drag_coefficient = 0.0,
       tangential_drag_coefficient = 0.0, linear_tangential_drag = {ct}, current = 0.0, {u} /
&ground point = 20.0, 0.0, normal = -1.0, 0.0, stiffness = {k}, damping = 2000.0,
        friction_coefficient = {mu_f}, friction_regularization_speed = 1.0e-4 /
&solver t_end = 3.0, output_interval = 0.05 /
""")
    proc = run("run", "slide.nml", "--set", "output.file='slide.h5'")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "slide.h5") as f:
        qdot = f["state/qdot"][-1]
        x = f["state/q"][-1, :, 0]
    assert abs(qdot[:, 1].mean() / (u - mu_f * w / ct) - 1) < 1e-6, qdot[:, 1].mean()
    assert abs((x.mean() - 20.0) / (w / k) - 1) < 1e-6


def test_a_line_falling_end_first_has_the_tangential_drag_and_added_mass(run, tmp_path):
    """A vertical line released in water falls along its axis: v(t) = v_t tanh(t/tau) with
    v_t = sqrt(2 w' / (rho C_t pi d)) (the skin friction on the wetted area) and
    tau = (mu + C_at rho A) v_t / w' (the tangential added mass), to 1e-8 of v_t."""
    mu, d, ct, cat = 0.5, 0.01, 0.5, 0.3
    (tmp_path / "fall.nml").write_text(f"""
&rope length = 1.0, mass_per_length = {mu}, axial_stiffness = 1.0e5, bending_stiffness = 1.0,
      diameter = {d} /
&model kind = 'rfem', elements = 10 /
&supports top = 'free', bottom = 'free', top_anchor = 1.0, 0.0 /
&initial shape = 'straight', angle_deg = 0.0 /
&effects water = .true., drag = .true. /
&fluid density = {RHO}, surface = 0.0, normal_drag_coefficient = 1.2,
       tangential_drag_coefficient = {ct}, added_mass_coefficient = 1.0,
       tangential_added_mass_coefficient = {cat} /
&solver t_end = 2.0, output_interval = 0.01, rtol = 1e-9, atol = 1e-12 /
""")
    proc = run("run", "fall.nml", "--set", "output.file='fall.h5'")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "fall.h5") as f:
        t = f["time"][()]
        v = f["state/qdot"][:, :, 0].mean(axis=1)
        sideways = np.abs(f["state/qdot"][:, :, 1]).max()
    w = (mu - RHO * area(d)) * G
    v_t = sqrt(2 * w / (RHO * ct * pi * d))
    tau = (mu + cat * RHO * area(d)) * v_t / w
    assert np.max(np.abs(v - v_t * np.tanh(t / tau))) < 1e-8 * v_t
    assert sideways == 0.0
    # the normal added mass along the axis would start it visibly slower
    tau_normal = (mu + RHO * area(d)) * v_t / w
    assert np.max(np.abs(v - v_t * np.tanh(t / tau_normal))) > 0.01 * v_t


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_the_tangential_added_mass_slows_the_axial_modes(run, tmp_path, kind):
    """The axial mode of a line hanging under water carries the tangential added mass only:
    omega(C_at) / omega(0) = sqrt(mu / (mu + C_at rho A)) on the same mesh (measured to
    1e-13), whatever the normal added mass."""
    mu, d, cat = 0.5, 0.02, 0.5

    def axial_omega(c_at):
        (tmp_path / "axial.nml").write_text(f"""
&rope length = 2.0, mass_per_length = {mu}, axial_stiffness = 200.0, diameter = {d} /
&model kind = '{kind}', elements = 20 /
&supports top = 'pinned', bottom = 'free' /
&initial shape = 'hanging' /
&effects water = .true. /
&fluid density = {RHO}, surface = -1.0, added_mass_coefficient = 1.0,
       tangential_added_mass_coefficient = {c_at} /
""")
        proc = run("modes", "axial.nml", "--count", "16", "-o", "axial.h5", "--force")
        assert proc.returncode == 0, proc.stderr
        with h5py.File(tmp_path / "axial.h5") as f:
            omega = f["modes/omega"][()]
            axial = f["modes/axial_fraction"][()]
        assert axial.max() > 0.99, axial
        return omega[np.argmax(axial)]

    ratio = axial_omega(cat) / axial_omega(0.0)
    assert abs(ratio / sqrt(mu / (mu + cat * RHO * area(d))) - 1) < 1e-9, ratio


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_a_line_heaved_through_the_surface(run, tmp_path, kind):
    """A stiff line hanging half under water, its top heaved x = a sin(Omega t): with the
    wet length w = w0 + x, Lagrange's equations of T_a = m_at w x'^2 / 2 give the water's
    force -(m_at w x'' + m_at x'^2 / 2), so the top's reaction is
    R = -(mu g L - rho g A w0) + (rho g A a - (mu L + m_at w0) a Omega^2) sin Omega t
        + m_at a^2 Omega^2 (-1/4 + 3/4 cos 2 Omega t).
    The Morison form (the force -m_at w x'' alone) gives -1/2 + 1/2 cos 2 Omega t.
    Measured at n = 10: within 4e-6 N and 0.1 % of the second harmonic (RFEM), 5e-7 N
    and 1e-5 (MPP)."""
    mu, d, cat, a, freq, surface = 0.5, 0.02, 1.0, 0.02, 1.0, 0.55
    (tmp_path / "heave.nml").write_text(f"""
&rope length = 1.0, mass_per_length = {mu}, axial_stiffness = 1.0e7, bending_stiffness = 0.0,
      axial_damping = 5000.0, diameter = {d} /
&model kind = '{kind}', elements = 10 /
&supports top = 'pinned', bottom = 'free', top_motion = 'harmonic', top_amplitude = {a}, 0.0,
          top_frequency = {freq}, top_ramp_time = 1.0 /
&initial shape = 'equilibrium' /
&effects water = .true. /
&fluid density = {RHO}, surface = {surface}, added_mass_coefficient = 1.0,
       tangential_added_mass_coefficient = {cat} /
&solver t_end = 3.0, output_interval = 0.005, rtol = 1e-9, atol = 1e-12 /
""")
    proc = run("run", "heave.nml", "--set", "output.file='heave.h5'")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "heave.h5") as f:
        t = f["time"][()]
        reaction = f["supports/top/reaction"][:, 0]
    after_ramp = t > 1.0
    t, reaction = t[after_ramp], reaction[after_ramp]
    omega = 2 * pi * freq
    basis = np.stack([np.ones_like(t), np.sin(omega * t), np.cos(omega * t),
                      np.sin(2 * omega * t), np.cos(2 * omega * t)], axis=1)
    c = np.linalg.lstsq(basis, reaction, rcond=None)[0]
    m_at, wet = cat * RHO * area(d), 1.0 - surface
    second = m_at * a * a * omega * omega
    assert abs(c[0] - (-(mu * G - RHO * G * area(d) * wet) - second / 4)) < 2e-5, c
    assert abs(c[1] - (RHO * G * area(d) * a - (mu + m_at * wet) * a * omega ** 2)) < 2e-5, c
    assert abs(c[4] - 0.75 * second) < 0.01 * second, (c, second)


def test_no_drag_above_the_surface(run, tmp_path):
    """A horizontal line 1 m above the water, drag on: it falls freely, g t^2 / 2, until it
    reaches the surface (the part in the air feels no drag)."""
    (tmp_path / "air.nml").write_text(f"""
&rope length = 1.0, mass_per_length = 0.5, axial_stiffness = 1.0e5, bending_stiffness = 1.0,
      diameter = 0.01 /
&model kind = 'rfem', elements = 10 /
&supports top = 'free', bottom = 'free', top_anchor = -1.0, 0.0 /
&initial shape = 'straight', angle_deg = 90.0 /
&effects water = .true., drag = .true. /
&fluid density = {RHO}, surface = 0.0, normal_drag_coefficient = 1.2,
       linear_normal_drag = 3.0 /
&solver t_end = 0.4, output_interval = 0.05, rtol = 1e-9, atol = 1e-12 /
""")
    proc = run("run", "air.nml", "--set", "output.file='air.h5'")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "air.h5") as f:
        t = f["time"][()]
        fall = f["state/q"][:, :, 0].mean(axis=1) + 1.0
    assert np.max(np.abs(fall - G * t ** 2 / 2)) < 1e-9
