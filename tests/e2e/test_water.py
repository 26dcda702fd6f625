"""A line in water (&effects water, the water below &fluid surface; docs/theory/water.md)
against physics: the top tension of a rope hanging partly in air and partly in water, the
submerged elastic catenary, the hanging chain's frequencies with added mass and submerged
weight (Bessel), a sinking line's terminal speed and time constant, and the energy balance
of a rope swinging through the surface with a current, for every method."""
from math import asinh, pi, sqrt

import h5py
import numpy as np
import pytest

G, RHO = 9.81, 1000.0
#: the first zeros of the Bessel function J0
J0_ZEROS = [2.404825557695773, 5.520078110286311, 8.653727912911013]


def write(tmp_path, name, text):
    (tmp_path / name).write_text(text)
    return name


def area(d):
    return pi * d * d / 4


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_top_tension_of_a_rope_partly_in_water(run, tmp_path, kind):
    """Hanging straight down, 2 m, the surface at 0.7123 m: the top carries the air part's
    weight and the wet part's weight less its buoyancy (EA 1e10: the stretch is 1e-9)."""
    mu, d, length, surface = 0.5, 0.01, 2.0, 0.7123
    scene = write(tmp_path, "part.nml", f"""
&rope length = {length}, mass_per_length = {mu}, axial_stiffness = 1.0e10, diameter = {d} /
&model kind = '{kind}', elements = 40 /
&supports top = 'pinned', bottom = 'free' /
&initial shape = 'hanging' /
&effects water = .true. /
&fluid density = {RHO}, surface = {surface} /
""")
    proc = run("statics", scene, "-o", "part.h5")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "part.h5") as f:
        top = -f["supports/top/reaction"][0][0]
    expected = mu * G * length - RHO * G * area(d) * (length - surface)
    assert abs(top / expected - 1) < 1e-6, (top, expected)


def elastic_catenary(length, span, w, ea):
    """Horizontal tension, sag and end tension of a catenary of unstretched length L and
    weight w per unstretched metre between two supports at one level `span` apart."""
    v = w * length / 2

    def span_of(h):
        return h * length / ea + h / w * (asinh(v / h) - asinh((v - w * length) / h))

    lo, hi = 1e-6, 1e6
    for _ in range(200):
        mid = sqrt(lo * hi)
        lo, hi = (lo, mid) if span_of(mid) > span else (mid, hi)
    h = sqrt(lo * hi)
    sag = (sqrt(h * h + v * v) - h) / w + w * length ** 2 / (8 * ea)
    return h, sag, sqrt(h * h + v * v)


@pytest.mark.parametrize("kind,n", [("rfem", 100), ("mpp", 150)])
def test_submerged_elastic_catenary(run, tmp_path, kind, n):
    """10 m of chain (EI = 0, EA 2 kN) under water between pins 8 m apart: sag, horizontal
    tension and end tension of the elastic catenary with the submerged weight, to 1e-4
    (stiff pins: a support's own spring would add an element's compliance)."""
    length, span, mu, ea, d = 10.0, 8.0, 0.5, 2.0e3, 0.01
    h, sag, t_end = elastic_catenary(length, span, (mu - RHO * area(d)) * G, ea)
    scene = write(tmp_path, "cat.nml", f"""
&rope length = {length}, mass_per_length = {mu}, axial_stiffness = {ea}, diameter = {d} /
&model kind = '{kind}', elements = {n} /
&supports top = 'pinned', bottom = 'pinned', top_anchor = 5.0, 0.0,
          bottom_anchor = 5.0, {span}, support_stiffness_factor = 1000.0 /
&initial shape = 'hanging' /
&effects water = .true. /
&fluid density = {RHO}, surface = 0.0 /
""")
    proc = run("statics", scene, "-o", "cat.h5", timeout=900)
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "cat.h5") as f:
        points = f["rope/points"][0]
        reaction = f["supports/top/reaction"][0]
    assert abs((points[:, 0].max() - 5.0) / sag - 1) < 1e-4
    assert abs(abs(reaction[1]) / h - 1) < 1e-4
    assert abs(np.hypot(*reaction) / t_end - 1) < 1e-4


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_hanging_chain_frequencies_in_water(run, tmp_path, kind):
    """A chain hanging under water: omega_k = (j_0k / 2) sqrt(w' / (m' L)) with the
    submerged weight w' and the mass with the added mass m' = mu + C_a rho A, to the
    model's discretization error at n = 100 (the same as in air); the RFEM carries the
    added mass in its elements' blocks, the MPP in its rods' inertia."""
    length, mu, d, ca = 2.0, 0.5, 0.01, 1.0
    scene = write(tmp_path, "chain.nml", f"""
&rope length = {length}, mass_per_length = {mu}, axial_stiffness = 1.0e7, diameter = {d} /
&model kind = '{kind}', elements = 100 /
&supports top = 'pinned', bottom = 'free' /
&initial shape = 'hanging' /
&effects water = .true. /
&fluid density = {RHO}, surface = -1.0, added_mass_coefficient = {ca} /
""")
    proc = run("modes", scene, "--count", "3", "-o", "modes.h5")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "modes.h5") as f:
        omega = f["modes/omega"][:3]
    weight = (mu - RHO * area(d)) * G
    expected = np.array(J0_ZEROS) / 2 * np.sqrt(weight / ((mu + ca * RHO * area(d)) * length))
    assert np.all(np.abs(omega / expected - 1) < [1e-6, 1e-4, 5e-4]), (omega, expected)
    # the added mass is what lowers them: without it they would be 8 % higher
    without = np.array(J0_ZEROS) / 2 * np.sqrt(weight / (mu * length))
    assert np.all(omega < 0.95 * without)


def test_a_sinking_line_reaches_the_terminal_speed_with_the_added_mass_time_constant(
        run, tmp_path):
    """A horizontal line, free at both ends, released in water: it sinks broadside with
    v(t) = v_t tanh(t / tau), v_t = sqrt(2 w' / (rho C_n d)) from buoyancy, gravity and
    drag, and tau = (mu + C_a rho A) v_t / w' from the mass with the added mass."""
    mu, d, cn, ca = 0.5, 0.01, 1.2, 1.0
    scene = write(tmp_path, "sink.nml", f"""
&rope length = 1.0, mass_per_length = {mu}, axial_stiffness = 1.0e5, bending_stiffness = 1.0,
      diameter = {d} /
&model kind = 'rfem', elements = 10 /
&supports top = 'free', bottom = 'free', top_anchor = 1.0, 0.0 /
&initial shape = 'straight', angle_deg = 90.0 /
&effects water = .true., drag = .true. /
&fluid density = {RHO}, surface = 0.0, normal_drag_coefficient = {cn},
       tangential_drag_coefficient = 0.0, added_mass_coefficient = {ca} /
&solver t_end = 1.0, output_interval = 0.005, rtol = 1e-9, atol = 1e-12 /
""")
    proc = run("run", scene, "--set", "output.file='sink.h5'")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "sink.h5") as f:
        t = f["time"][()]
        v = f["state/qdot"][:, :, 0].mean(axis=1)
    weight = (mu - RHO * area(d)) * G
    v_t = sqrt(2 * weight / (RHO * cn * d))
    tau = (mu + ca * RHO * area(d)) * v_t / weight
    model = v_t * np.tanh(t / tau)
    assert abs(v[-1] / v_t - 1) < 1e-5
    assert np.max(np.abs(v - model)) < 1e-6 * v_t
    tau_dry = mu * v_t / weight        # without the added mass: a visibly faster start
    assert np.max(np.abs(v - v_t * np.tanh(t / tau_dry))) > 0.01 * v_t


@pytest.mark.parametrize("kind,method", [("rfem", "auto"), ("rfem", "erk"), ("rfem", "mebdf"),
                                         ("rfem", "cvode"), ("mpp", "auto"), ("mpp", "cvode")])
def test_energy_balance_through_the_surface(run, tmp_path, kind, method):
    """A chain swinging through the surface with a current, tangential added mass, drag
    and material damping: T + V + dissipated - work stays at E0 to the tolerance (the added
    mass's kinetic energy and the current's potential counted, the buoyancy's potential,
    the drag's dissipation and the current's work on it)."""
    scene = write(tmp_path, "swing.nml", """
&rope length = 3.0, mass_per_length = 0.0818, axial_stiffness = 1.0e4, axial_damping = 5.0,
      bending_stiffness = 1.0e-3, diameter = 0.003654 /
&model kind = '%s', elements = 20 /
&supports top = 'pinned', bottom = 'free' /
&initial shape = 'straight', angle_deg = 60.0 /
&effects water = .true., drag = .true. /
&fluid density = 1000.0, surface = 1.0, normal_drag_coefficient = 1.5,
       tangential_drag_coefficient = 0.1, added_mass_coefficient = 1.0,
       tangential_added_mass_coefficient = 0.5, current = 0.05, 0.2 /
&solver t_end = 2.0, rtol = 1e-7, atol = 1e-9 /
""" % kind)
    proc = run("run", scene, "--set", f"solver.method='{method}'", "--set",
               f"output.file='{method}.h5'")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / f"{method}.h5") as f:
        e = {k: f["energy"][k][()] for k in ("kinetic", "elastic", "gravity", "dissipated",
                                              "support_work")}
    balance = e["kinetic"] + e["elastic"] + e["gravity"] + e["dissipated"] - e["support_work"]
    scale = np.ptp(e["gravity"]) + e["kinetic"].max() + e["dissipated"][-1] + \
        np.abs(e["support_work"]).max()
    assert np.max(np.abs(balance - balance[0])) < 10 * 1e-7 * scale, method
    assert e["dissipated"][-1] > 0 and np.abs(e["support_work"]).max() > 0


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_a_damped_run_settles_on_the_submerged_catenary(run, tmp_path, kind):
    """Started from the catenary displaced along its first mode by 0.3 m, the chain
    damped by its material and the water's drag comes to rest on the statics' equilibrium
    (to 1e-6 of the sag) and so on the elastic catenary (1e-4)."""
    length, span, mu, ea, d = 10.0, 8.0, 0.5, 2.0e3, 0.01
    h, sag, t_end = elastic_catenary(length, span, (mu - RHO * area(d)) * G, ea)
    common = f"""
&rope length = {length}, mass_per_length = {mu}, axial_stiffness = {ea}, diameter = {d},
      axial_damping = 20.0 /
&model kind = '{kind}', elements = 100 /
&supports top = 'pinned', bottom = 'pinned', top_anchor = 5.0, 0.0,
          bottom_anchor = 5.0, {span}, support_stiffness_factor = 1000.0 /
&effects water = .true., drag = .true. /
&fluid density = {RHO}, surface = 0.0, normal_drag_coefficient = 1.2,
       linear_normal_drag = 5.0 /
&solver t_end = 15.0, output_interval = 0.1 /
"""
    static = write(tmp_path, "static.nml", common + "&initial shape = 'hanging' /\n")
    moving = write(tmp_path, "moving.nml", common +
                   "&initial shape = 'mode', mode = 1, mode_amplitude = 0.3 /\n")
    assert run("statics", static, "-o", "static.h5").returncode == 0
    proc = run("run", moving, "--set", "output.file='moving.h5'")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "static.h5") as s, h5py.File(tmp_path / "moving.h5") as m:
        sag_static = s["rope/points"][0, :, 0].max() - 5.0
        start = m["rope/points"][0, :, 0].max() - 5.0
        end = m["rope/points"][-1, :, 0].max() - 5.0
        reaction = m["supports/top/reaction"][-1]
    assert abs(start - sag_static) > 0.01           # it did move
    assert abs(end / sag_static - 1) < 1e-6
    assert abs(end / sag - 1) < 1e-4
    assert abs(np.hypot(*reaction) / t_end - 1) < 1e-4


@pytest.mark.parametrize("kind,method", [("rfem", "cvode"), ("mpp", "cvode"), ("mpp", "mebdf")])
def test_a_rigid_pendulum_under_water_swings_with_the_added_moment_of_inertia(run, tmp_path,
                                                                               kind, method):
    """A rigid rod pinned at the top (two elements, EI 1e4: the bending the swing causes
    changes the period by about 1e-5; the joint's stiff modes damped, which the rigid
    swing does not feel), fully under water, swinging 1 degree: a compound pendulum,
    omega^2 = (w' L / 2) / ((mu + m_a) L^2 / 3), with the submerged weight w' and the added
    mass m_a = C_a rho A per metre moving with each point of the rod: each element carries
    it in translation and, about its centre, in rotation (m_a l^3 / 12: together 1/16 of
    the rod's added inertia about the pin at two elements). MEBDF integrates the MPP in its
    implicit form."""
    length, mu, d, ca = 1.0, 0.5, 0.01, 1.0
    scene = write(tmp_path, "pendulum.nml", f"""
&rope length = {length}, mass_per_length = {mu}, axial_stiffness = 1.0e7,
      bending_stiffness = 1.0e4, axial_damping = 1.0e3, bending_damping = 5.0, diameter = {d} /
&model kind = '{kind}', elements = 2 /
&supports top = 'pinned', bottom = 'free' /
&initial shape = 'straight', angle_deg = 1.0 /
&effects water = .true. /
&fluid density = {RHO}, surface = -1.0, added_mass_coefficient = {ca} /
&solver method = '{method}', t_end = 6.0, output_interval = 0.001, rtol = 1e-9, atol = 1e-12 /
""")
    proc = run("run", scene, "--set", "output.file='pendulum.h5'")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "pendulum.h5") as f:
        t = f["time"][()]
        sideways = f["rope/points"][:, -1, 1]
    # the period from the upward zero crossings (linear interpolation between records)
    up = np.nonzero((sideways[:-1] < 0) & (sideways[1:] >= 0))[0]
    crossings = t[up] - sideways[up] * (t[up + 1] - t[up]) / (sideways[up + 1] - sideways[up])
    assert len(crossings) >= 2
    period = np.mean(np.diff(crossings))
    weight = (mu - RHO * area(d)) * G
    m_a = ca * RHO * area(d)
    expected = 2 * pi / sqrt(1.5 * weight / ((mu + m_a) * length))
    # (the amplitude's own lengthening, theta^2 / 16, is 2e-5)
    assert abs(period / expected - 1) < 2e-4, (period, expected)
    # without the elements' rotary added inertia it would swing 0.42 % faster
    without = 2 * pi / sqrt(1.5 * weight / ((mu + 15 / 16 * m_a) * length))
    assert abs(period / without - 1) > 4e-3
