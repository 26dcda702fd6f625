"""An independent RFEM implementation for the end-to-end tests (numpy only, no code shared
with ropedyn): the paper's model written from the paper's equations as docs/theory/rfem.md states them, as
energies alone. Forces are derived numerically, not by hand: the strains s(q) of every
spring-damping element are evaluated at q + i h e_j (complex-step differentiation, exact to
rounding for h = 1e-30), which gives their gradients G = ds/dq, and then

    A q'' = -dV/dq - dD/dq' = -G^T (C s + B G q') + gravity,
    V = sum C s^2/2 - sum m g x,   D = sum B (G q')^2/2,

with A = diag(m_i, m_i, J_i). Integrated with classical fixed-step RK4 (the dissipated
energy integral of 2D = sum B (G q')^2 as an extra component). The fastest mode at n = 6
has |lambda| = 1.16e3 1/s (RK4 is stable for dt < 2.4e-3 s). Its error over the paper's
first 2 s, against dt = 1.25e-4 s: tip 6.3e-7 m, dissipated energy 2.5e-8 J, T + V 4.2e-8 J
at dt = 5e-4 s; 3.7e-8 m, 1.2e-9 J, 2.5e-9 J at dt = 2.5e-4 s (fourth order).

Conventions (docs/theory/rfem.md): x down, y horizontal, angles from x towards y; elements 1 and n of
length dl/2, the others dl = L/(n - 1); m_i = rho A l_i, J_i = m_i (l_i^2/12 + d^2/16);
SDE strains in the frame of the upper element: e_a.(A_b - B_a), n_a.(A_b - B_a),
phi_b - phi_a with C = (EA, GA/chi, EI)/dl and B = (eta A, eta_bar A/chi, eta I)/dl; a
pinned top is an isotropic spring and damper (Cx, Bx) on both global components of
A_1 - P_top.
"""
import numpy as np


class Rope:
    """The paper's rope (Table 1 as read in docs/theory/rfem.md) discretized with n elements, top
    pinned at the origin, bottom free."""

    def __init__(self, n, length=1.0, diameter=0.005, density=6000.0, young=35e6, shear=14e6,
                 eta=1e3, eta_bar=None, chi=10.0 / 9.0, g=9.81):
        eta_bar = eta * shear / young if eta_bar is None else eta_bar
        area = np.pi * diameter**2 / 4
        inertia = np.pi * diameter**4 / 64
        dl = length / (n - 1)
        self.n, self.g = n, g
        self.l = np.full(n, dl)
        self.l[0] = self.l[-1] = dl / 2
        self.m = density * area * self.l
        self.J = self.m * (self.l**2 / 12 + diameter**2 / 16)
        self.mass = np.repeat(self.m, 3).reshape(n, 3)
        self.mass[:, 2] = self.J
        self.mass = self.mass.ravel()
        internal_c = [young * area / dl, shear * area / (chi * dl), young * inertia / dl]
        internal_b = [eta * area / dl, eta_bar * area / (chi * dl), eta * inertia / dl]
        # strain order: (tension, shear, bending) of SDEs 2 .. n, then the top pin (x, y)
        self.C = np.concatenate([np.repeat(internal_c, n - 1),
                                 [young * area / dl, young * area / dl]])
        self.B = np.concatenate([np.repeat(internal_b, n - 1),
                                 [eta * area / dl, eta * area / dl]])

    def strains(self, q):
        """Strains of every SDE for configurations q (..., 3n), real or complex."""
        x, y, phi = q[..., 0::3], q[..., 1::3], q[..., 2::3]
        ex, ey = np.cos(phi), np.sin(phi)
        half = self.l / 2
        # end B of the upper element a, start A of the lower element b
        bx, by = x[..., :-1] + half[:-1] * ex[..., :-1], y[..., :-1] + half[:-1] * ey[..., :-1]
        ax, ay = x[..., 1:] - half[1:] * ex[..., 1:], y[..., 1:] - half[1:] * ey[..., 1:]
        dx, dy = ax - bx, ay - by
        ea_x, ea_y = ex[..., :-1], ey[..., :-1]
        tension = ea_x * dx + ea_y * dy
        shear = -ea_y * dx + ea_x * dy
        bending = phi[..., 1:] - phi[..., :-1]
        top_x = x[..., 0] - half[0] * ex[..., 0]
        top_y = y[..., 0] - half[0] * ey[..., 0]
        return np.concatenate([tension, shear, bending, top_x[..., None], top_y[..., None]],
                              axis=-1)

    def gradients(self, q):
        """ds/dq, shape (strains, 3n), by complex steps."""
        h = 1e-30
        probes = q + 1j * h * np.eye(q.size)
        return (self.strains(probes).imag / h).T

    def initial_state(self, angle_deg):
        """Straight, unstretched, at rest from the top anchor at angle_deg."""
        a = np.radians(angle_deg)
        centre = np.cumsum(self.l) - self.l / 2
        q = np.zeros(3 * self.n)
        q[0::3], q[1::3], q[2::3] = centre * np.cos(a), centre * np.sin(a), a
        return np.concatenate([q, np.zeros(3 * self.n), [0.0]])

    def rhs(self, z):
        """d/dt of (q, q', dissipated)."""
        k = 3 * self.n
        q, v = z[:k], z[k:2 * k]
        s = self.strains(q)
        grad = self.gradients(q)
        rate = grad @ v
        force = -grad.T @ (self.C * s + self.B * rate)
        force[0::3] += self.m * self.g
        return np.concatenate([v, force / self.mass, [np.sum(self.B * rate**2)]])

    def energy(self, z):
        """Kinetic + elastic + gravity energy of state z, J."""
        k = 3 * self.n
        q, v = z[:k], z[k:2 * k]
        return (0.5 * np.sum(self.mass * v**2) + 0.5 * np.sum(self.C * self.strains(q)**2)
                - self.g * np.sum(self.m * q[0::3]))

    def tip(self, z):
        """Free end of the last element (x, y), m."""
        x, y, phi = z[3 * self.n - 3:3 * self.n]
        return np.array([x + self.l[-1] / 2 * np.cos(phi), y + self.l[-1] / 2 * np.sin(phi)])


def integrate(rope, z, t_end, dt, record_every):
    """RK4 from t = 0; returns the times and states every `record_every` steps."""
    steps = int(round(t_end / dt))
    times, states = [0.0], [z.copy()]
    for i in range(1, steps + 1):
        k1 = rope.rhs(z)
        k2 = rope.rhs(z + 0.5 * dt * k1)
        k3 = rope.rhs(z + 0.5 * dt * k2)
        k4 = rope.rhs(z + dt * k3)
        z = z + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        if i % record_every == 0:
            times.append(i * dt)
            states.append(z.copy())
    return np.array(times), np.array(states)
