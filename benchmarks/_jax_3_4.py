"""The §3.4 peer of ``vs_jax.py``: a rotating-wing Drag PARITY design sweep as a researcher's JAX +
diffrax script would write it, from the model's equations (docs/concepts.md, thesis §3.2,
App. A), not from paritysim's code paths.

Two wings on the stroke plane (deviation θ held at 0 on α2 = 90° shoulders), each with stroke φ
and a passive rotation ψ about the hinge (spring ``k ψ``); the two strokes driven through the
linear map of eq. 2.15 (``φL = −T q1 + T hL q2``, ``φR = −T q1 − T hR q2``) by the actuator
``F(t) − K1 q1`` on ``q1`` and the balance spring ``−K2 q2`` on the whippletree ``q2``; the
drivetrain is massless, so its load reaches the wings as ``τ_φ = J⁻ᵀ Q``.

Per wing, with ``a = (cos ψ, −sin ψ, 0)`` the stroke axis in the wing frame,
``ω = φ̇ a + ψ̇ ẑ`` and ``I`` the wing's inertia tensor (App. A with θ ≡ 0):

    [aᵀIa  (Ia)_z] [φ̈]   [a·τ − a·v + τ_φ]
    [(Ia)_z  I_zz] [ψ̈] = [τ_z − v_z − k ψ ],   v = I (φ̇ψ̇ (−sin ψ, −cos ψ, 0)) + ω × Iω,

and the quasi-steady blade element (§3.2.4, eqs. 3.5-3.11, α sign of docs/errata.md#5):
``W² = ω_x² + ω_y²``, ``σ = sgn ω_x``, ``α = atan2(|ω_x|, ω_y)``, Dickinson's fits extended past
90° by flat-plate symmetry, ``C_N = C_L cos α + C_D sin α``, ``C_T = C_D cos α − C_L sin α``,
``d_cp = 0.82 α/π + 0.05``, and the torque in the wing frame

    τ = (−Ω1 σ W² C_N,  −Ω1 W² C_T,  −(Ω3 d_cp − Ω4) σ W² C_N − Ω2 C_rd ω_z |ω_z|).

Smooth through stroke reversal as a script writes it: ``jnp.sign``, ``|x| x``, ``jnp.where``; no
event location. The body torques (yaw) are ``R_x(φ) R_z(ψ) (τ − (I ω̇ + ω × Iω))`` per wing, the
left one mirrored ``(−x, −y, z)``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import polars as pl

import paritysim as ps
from paritysim.aero import DEFAULT_ROTATIONAL_DAMPING

# The metrics compared with paritysim's (names as ps.sweep reports them).
METRICS = (
    "yaw_total_mean",
    "left_stroke_amplitude",
    "right_stroke_amplitude",
    "left_stroke_mean",
    "right_stroke_mean",
    "left_rotation_amplitude",
    "right_rotation_amplitude",
)
CD_OFFSET, CL_OFFSET = math.radians(9.82), math.radians(7.20)
D_CP_SLOPE = 0.82 / math.pi


def constants(spec: ps.Simulation) -> dict:
    """What the script hard-codes, read from the device spec (the swept fields are per point)."""
    d, a = spec.drivetrain, spec.actuator
    ratio = d.arm_ratio
    h_l, h_r = 2 * d.arm_length_mm * ratio / (1 + ratio), 2 * d.arm_length_mm / (1 + ratio)
    t = d.transmission_ratio
    jac = np.array([[-t, t * h_l], [-t, -t * h_r]])
    assert a.dc_offset == "ignore" and a.waveform.kind == "sine"
    return dict(
        inertia=np.array([np.array(w.inertia, dtype=float) for w in spec.wings]),
        omegas=np.array([[w.aero.omega1, w.aero.omega2, w.aero.omega3, w.aero.omega4] for w in spec.wings]),
        c_rd=[DEFAULT_ROTATIONAL_DAMPING if w.aero.rotational_damping is None else w.aero.rotational_damping for w in spec.wings],
        jinv=np.linalg.inv(jac),
        k1=a.stiffness,
        k2=d.balance_spring,
        force=a.force_per_volt * a.waveform.amplitude_v,
        w=2 * math.pi * a.waveform.frequency_hz * 1e-3,  # rad/ms
        phase=a.waveform.phase,
    )


def model(c: dict, jnp) -> tuple[Callable, Callable]:
    """``rhs(t, y, (hinge, omegas_right))`` and ``yaw(t, y, args)`` (net yaw torque, mN·mm) on
    ``y = (φL, ψL, φR, ψR, φ̇L, ψ̇L, φ̇R, ψ̇R)``."""
    inertia, jinv = jnp.asarray(c["inertia"]), jnp.asarray(c["jinv"])
    omegas_left, c_rd = jnp.asarray(c["omegas"][0]), c["c_rd"]
    k1, k2, force, w, phase = c["k1"], c["k2"], c["force"], c["w"], c["phase"]

    def fit(alpha):
        cd = 1.92 - 1.55 * jnp.cos(2.04 * alpha - CD_OFFSET)  # eq. 3.5
        cl = 0.225 + 1.58 * jnp.sin(2.13 * alpha - CL_OFFSET)  # eq. 3.6
        return cl, cd

    def aero(om, omega, crd):
        wx, wy, wz = omega
        w2 = wx * wx + wy * wy
        sigma = jnp.sign(wx)
        alpha = jnp.arctan2(jnp.abs(wx), wy)
        below = alpha <= math.pi / 2
        cl, cd = fit(jnp.where(below, alpha, math.pi - alpha))
        cl = jnp.where(below, cl, -cl)
        sa, ca = jnp.sin(alpha), jnp.cos(alpha)
        cn, ct = cl * ca + cd * sa, cd * ca - cl * sa
        d_cp = D_CP_SLOPE * alpha + 0.05
        return jnp.stack([
            -om[0] * sigma * w2 * cn,
            -om[0] * w2 * ct,
            -(om[2] * d_cp - om[3]) * sigma * w2 * cn - om[1] * crd * wz * jnp.abs(wz),
        ])  # fmt: skip

    def wing(i, om, crd, hinge, phi_dot, psi, psi_dot, drive):
        s, co = jnp.sin(psi), jnp.cos(psi)
        inn = inertia[i]
        a = jnp.stack([co, -s, 0.0 * s])
        ia, iz = inn @ a, inn[:, 2]
        omega = a * phi_dot + jnp.array([0.0, 0.0, 1.0]) * psi_dot
        i_omega = ia * phi_dot + iz * psi_dot
        v = inn @ (jnp.stack([-s, -co, 0.0 * s]) * (phi_dot * psi_dot)) + jnp.cross(omega, i_omega)
        tau = aero(om, omega, crd)
        f_phi = a @ tau - a @ v + drive
        f_psi = tau[2] - v[2] - hinge * psi
        m_pp, m_ps, m_ss = a @ ia, ia[2], inn[2, 2]
        det = m_pp * m_ss - m_ps * m_ps
        phi_ddot, psi_ddot = (m_ss * f_phi - m_ps * f_psi) / det, (m_pp * f_psi - m_ps * f_phi) / det
        return phi_ddot, psi_ddot, (a, omega, i_omega, v, tau, s, co)

    def drive(t, y):
        q = jinv @ y[jnp.array([0, 2])]
        load = jnp.stack([force * jnp.sin(w * t + phase) - k1 * q[0], -k2 * q[1]])
        return jinv.T @ load

    def both(t, y, args):
        hinge, omegas_right = args
        tau_drive = drive(t, y)
        left = wing(0, omegas_left, c_rd[0], hinge, y[4], y[1], y[5], tau_drive[0])
        right = wing(1, omegas_right, c_rd[1], hinge, y[6], y[3], y[7], tau_drive[1])
        return left, right

    def rhs(t, y, args):
        left, right = both(t, y, args)
        return jnp.stack([y[4], y[5], y[6], y[7], left[0], left[1], right[0], right[1]])

    def yaw(t, y, args):
        total = 0.0
        for k, (phi_ddot, psi_ddot, (a, omega, i_omega, v, tau, s, co)) in enumerate(both(t, y, args)):
            phi = y[2 * k]
            inn = inertia[k]
            omega_dot = a * phi_ddot + jnp.array([0.0, 0.0, 1.0]) * psi_ddot + jnp.stack([-s, -co, 0.0 * s]) * (y[4 + 2 * k] * y[5 + 2 * k])
            r = tau - (inn @ omega_dot + jnp.cross(omega, i_omega))
            # y component of R_x(φ) R_z(ψ) r; the left wing mirrored.
            body_y = jnp.cos(phi) * (s * r[0] + co * r[1]) - jnp.sin(phi) * r[2]
            total = total + (-body_y if k == 0 else body_y)
        return total

    return rhs, yaw


def runners(spec: ps.Simulation, cycles: int, samples: int, rtol: float, atol: float) -> tuple[Callable, Callable | None] | str:
    """(jit(vmap), shard_map over 2 devices or None) of ``run(hinge[n], omegas_right[n, 4]) ->
    metrics[n, len(METRICS)]``, or the reason JAX is skipped. Each point: ``cycles`` drive
    periods from rest (Dopri5, PID step control), the metrics of the last one from
    ``samples + 1`` samples (the closing one left out of means, as paritysim's)."""
    try:
        import diffrax
        import jax
        import jax.numpy as jnp
    except ImportError as e:  # the optional `bench` extra
        return f"JAX/diffrax not installed ({e.name}); install the `bench` extra"
    jax.config.update("jax_enable_x64", True)
    c = constants(spec)
    rhs, yaw = model(c, jnp)
    period = 2 * math.pi / c["w"]
    ts = jnp.linspace((cycles - 1) * period, cycles * period, samples + 1)

    def one(hinge, omegas_right):
        args = (hinge, omegas_right)
        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(rhs), diffrax.Dopri5(), t0=0.0, t1=cycles * period, dt0=None, y0=jnp.zeros(8), args=args,
            saveat=diffrax.SaveAt(ts=ts), stepsize_controller=diffrax.PIDController(rtol=rtol, atol=atol), max_steps=2000 * cycles,
        )  # fmt: skip
        ys = sol.ys
        body = ys[:-1]
        yaw_mean = jnp.mean(jax.vmap(lambda t, y: yaw(t, y, args))(ts[:-1], body))

        def half_span(v):
            return 0.5 * (v.max() - v.min())

        return jnp.stack([
            yaw_mean,
            half_span(ys[:, 0]), half_span(ys[:, 2]),
            jnp.mean(body[:, 0]), jnp.mean(body[:, 2]),
            half_span(ys[:, 1]), half_span(ys[:, 3]),
        ])  # fmt: skip

    vmapped = jax.jit(jax.vmap(one))
    sharded = None
    if len(jax.devices()) >= 2:
        from jax.sharding import Mesh
        from jax.sharding import PartitionSpec as P

        try:
            from jax import shard_map  # JAX >= 0.6
        except ImportError:
            from jax.experimental.shard_map import shard_map
        mesh = Mesh(np.array(jax.devices()[:2]), ("points",))
        specs = dict(mesh=mesh, in_specs=(P("points"), P("points")), out_specs=P("points"))
        try:
            mapped = shard_map(jax.vmap(one), **specs, check_vma=False)
        except TypeError:
            mapped = shard_map(jax.vmap(one), **specs, check_rep=False)
        sharded = jax.jit(mapped)

    def wrap(f, multiple: int):
        def run(hinge: np.ndarray, omegas_right: np.ndarray) -> np.ndarray:
            n = len(hinge)
            pad = -n % multiple  # shard_map splits the points evenly: repeat the last one
            hinge, omegas_right = np.concatenate([hinge, hinge[-1:].repeat(pad)]), np.concatenate([omegas_right, omegas_right[-1:].repeat(pad, axis=0)])
            return np.asarray(jax.block_until_ready(f(jnp.asarray(hinge), jnp.asarray(omegas_right))))[:n]

        return run

    return wrap(vmapped, 1), (wrap(sharded, 2) if sharded is not None else None)


def grid(spec: ps.Simulation, n: int) -> tuple[pl.DataFrame, np.ndarray, np.ndarray]:
    """The design grid of docs/tutorials/design-study-3-4.md, ``n`` × ``n``: hinge stiffness of
    both wings in [1.5, 4] mN·mm/rad × right membrane cut at the tip, 0-25 % of the span (the
    right wing's Ω1..Ω4 scaled by the stand-in outline's cut/uncut integrals, inertia kept).
    Rows for ``ps.sweep`` (cut outer, hinge inner) and the peer's ``hinge[n²]``,
    ``omegas_right[n², 4]``."""
    outline = ps.Planform.hmf_like()
    uncut = outline.omegas()
    right = spec.wings[1].aero
    base = np.array([right.omega1, right.omega2, right.omega3, right.omega4])
    hinges = np.linspace(1.5, 4.0, n)
    omegas = []
    for f in np.linspace(0.0, 0.25, n):
        cut = outline.cut(f, where="tip").omegas() if f > 0 else uncut
        omegas.append(base * np.array([cut[f"omega{k}"] / uncut[f"omega{k}"] for k in range(1, 5)]))
    hinge = np.tile(hinges, n)
    omegas_right = np.repeat(np.array(omegas), n, axis=0)
    rows = {"wings[*].springs.hinge.stiffness": hinge, **{f"wings.right.aero.omega{k}": omegas_right[:, k - 1] for k in range(1, 5)}}
    return pl.DataFrame(rows), hinge, omegas_right
