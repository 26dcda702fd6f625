"""Closed forms of docs/theory/statics-modes.md reproduced by the whole program, and the
paper's experiment against an independent implementation (tests/e2e/rfem_oracle.py)."""
import h5py
import numpy as np

import rfem_oracle


def test_paper_experiment_against_an_independent_implementation(run, tmp_path):
    """The paper's experiment with n = 6 (Table 1 rope, damping 1e3/400, released from
    75 deg) against tests/e2e/rfem_oracle.py, an independent RFEM written from the paper's equations as
    energies only (forces by complex-step derivatives of the strains, fixed-step RK4), over
    the first 2 s, before the motion's sensitivity grows: from 3 s on, two accurate
    solutions separate exponentially (5 s: 0.1 m at the tip, 8 % in the dissipated energy;
    a published "about 0.023 J in 5 s, 0.18 J in 30 s" of another implementation is in
    that regime and cannot be a sharp anchor). E0 = -m g (L/2) cos 75 deg = -0.1495603 J
    exactly. Measured at rtol 1e-8 (Debug build, oracle dt = 5e-4 s): tip 6.3e-7 m,
    dissipated 2.5e-8 J (of 1.486e-3 J at 2 s), T + V 4.2e-8 J, energy balance 1.1e-10 J;
    the bounds are about three times these (the balance's five). The differences are the
    oracle's own RK4 error (6.3e-7 m, 2.5e-8 J, 4.2e-8 J against dt = 1.25e-4 s); a wrong
    damping or stiffness constant moves the dissipated energy by 1e-5 J and more."""
    (tmp_path / "n6.nml").write_text(
        "&model kind = 'rfem', elements = 6 /\n"
        "&solver t_end = 2.0, output_interval = 0.1, rtol = 1e-8, atol = 1e-10 /\n")
    result = run("run", "n6.nml")
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "out" / "n6.h5") as f:
        e = {k: f["energy"][k][:] for k in f["energy"]}
        tip = f["rope/points"][:, -1, :]
    assert abs(e["total"][0] - (-0.1495603)) < 1e-7
    rope = rfem_oracle.Rope(6)
    times, states = rfem_oracle.integrate(rope, rope.initial_state(75.0), 2.0, 5e-4, 200)
    assert len(times) == len(tip)
    oracle_tip = np.array([rope.tip(z) for z in states])
    oracle_total = np.array([rope.energy(z) for z in states])
    assert np.max(np.abs(tip - oracle_tip)) < 2e-6
    assert np.max(np.abs(e["dissipated"] - states[:, -1])) < 6e-8
    assert abs(e["dissipated"][-1] - 1.4857e-3) < 1e-7      # the value itself, for the record
    assert np.max(np.abs(e["total"] - oracle_total)) < 1.2e-7
    balance = e["total"] + e["dissipated"] - e["support_work"]
    assert np.max(np.abs(balance - balance[0])) < 5e-10       # measured 1.1e-10 J


def test_axial_mode_of_hanging_rod(run, tmp_path):
    """A rope hung straight and unstretched rings in its axial modes. With a rigid top
    (support_stiffness_factor = 1000) the first mode is omega_1 = pi c/(2L) = 119.97 rad/s
    (c = sqrt(E/rho), gravity drops out); the Kelvin-Voigt dampers (B = (eta/E) C) give
    every mode the decay rate tau omega^2/2 with tau = eta/E; the mean tip stretch is
    w L^2/(2 EA) = 8.40857e-4 m. Measured at n = 10: 119.81 rad/s, decay 1.001 of the
    prediction, stretch 8.398e-4 m."""
    (tmp_path / "rod.nml").write_text(
        "&model kind = 'rfem', elements = 10 /\n"
        "&initial shape = 'hanging' /\n"
        "&supports support_stiffness_factor = 1000.0 /\n"
        "&solver t_end = 3.0, output_interval = 0.0002, rtol = 1e-8, atol = 1e-12 /\n")
    result = run("run", "rod.nml")
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "out" / "rod.h5") as f:
        t = f["time"][:]
        tip = f["rope/points"][:, -1, :]
    assert np.max(np.abs(tip[:, 1])) == 0.0, "a vertical rope stays vertical"
    sel = t > 1.0          # the higher modes (decay rate 9x, 25x, ...) have died out
    tt, x = t[sel], tip[sel, 0]
    s = x - x.mean()
    peaks = np.where((s[1:-1] > s[:-2]) & (s[1:-1] >= s[2:]))[0] + 1
    omega = 2 * np.pi / np.mean(np.diff(tt[peaks]))
    sigma = -np.polyfit(tt[peaks], np.log(s[peaks]), 1)[0]
    rho, e_mod, eta, length, g = 6000.0, 35e6, 1e3, 1.0, 9.81
    omega_1 = np.pi * np.sqrt(e_mod / rho) / (2 * length)
    assert abs(omega / omega_1 - 1) < 0.005, (omega, omega_1)
    tau = eta / e_mod
    assert abs(sigma / (tau * omega**2 / 2) - 1) < 0.03, sigma
    stretch = rho * g * length**2 / (2 * e_mod)
    assert abs((x.mean() - length) / stretch - 1) < 0.01, x.mean() - length


def test_a_trolley_stop_leaves_the_payload_swinging(run, tmp_path):
    """A gantry crane's emergency stop (docs/guide/examples.md): 12 m of wire (1 kg/m,
    EA = 1.2e7 N) with 2000 kg at its end, in the frame that travels with the trolley at
    v = 1 m/s: the trolley decelerates at a = v/tau for tau = 0.5 s. The swing's period at
    rest is the compound pendulum's, 2 pi sqrt(L' (M + m/3)/(g (M + m/2))) with the
    stretched length L'; after the stop the payload swings relative to the trolley by
    (2a/w^2) sin(w tau/2) (the linear pendulum driven by a for tau; 1.0970 m); at the
    bottom of the swing the top carries the weight W of wire and payload plus
    2 M g (1 - cos theta0) (163 N), the wire's axial mode damped (axial_damping).
    Measured at n = 5 (Debug): omega 0.9999996 of the formula, amplitude 0.99990 of it,
    tension at the bottom 19902.9 N against 19901.0 N; without the damping the axial mode
    rings by about 95 N on top."""
    rows = []
    for k in range(121):
        t = 0.05 * k
        rows.append(f"{t:.2f} 0.0 {-t * t if t <= 0.5 else -0.25 - (t - 0.5):.6f} 0.0")
    (tmp_path / "stop.dat").write_text("\n".join(rows) + "\n")
    (tmp_path / "stop.nml").write_text(
        "&model kind = 'rfem', elements = 5 /\n"
        "&rope length = 12.0, diameter = 0.016, mass_per_length = 1.0,"
        " axial_stiffness = 1.2e7, axial_damping = 3.2e5 /\n"
        "&supports end_compliance = 'split', top_motion = 'table', top_table = 'stop.dat' /\n"
        "&initial shape = 'equilibrium', angle_deg = 0.0 /\n"
        "&attachments mass_positions = 12.0, masses = 2000.0 /\n"
        "&solver t_end = 4.5 /\n")
    g, length, mu, mass, ea, v, tau = 9.81, 12.0, 1.0, 2000.0, 1.2e7, 1.0, 0.5
    wire = mu * length
    stretched = length + mass * g * length / ea + mu * g * length**2 / (2 * ea)
    omega = np.sqrt(g / stretched * (mass + wire / 2) / (mass + wire / 3))
    modes = run("modes", "stop.nml", "--count", "1", "-o", "m.h5")
    assert modes.returncode == 0, modes.stderr
    with h5py.File(tmp_path / "m.h5") as f:
        assert abs(f["modes/omega"][0] / omega - 1) < 1e-5, f["modes/omega"][0]
    result = run("run", "stop.nml", "--set", "output.file=r.h5")
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "r.h5") as f:
        t = f["time"][:]
        swing = f["rope/points"][:, -1, 1] - f["supports/top/position"][:, 1]
        top = np.hypot(*f["supports/top/reaction"][:].T)
    a = v / tau
    amplitude = 2 * a / omega**2 * np.sin(omega * tau / 2)
    assert abs(swing.max() / amplitude - 1) < 5e-4, (swing.max(), amplitude)
    theta0 = amplitude / stretched
    bottom = (wire + mass) * g + 2 * mass * g * (1 - np.cos(theta0))
    near = (t > 3.4) & (t < 4.1)           # the payload passes under the trolley at 3.73 s
    assert abs(top[near].max() - bottom) < 10.0, (top[near].max(), bottom)
