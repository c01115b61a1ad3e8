"""MuJoCo (MJCF) model of a five-bar and the state mapping between dextar and MuJoCo.

Each leg is a chain of two hinge bodies (proximal rod at its pivot, distal rod at the elbow);
the loop is closed by an equality ``connect`` between sites at the two distal tips. The point
mass at P (end-effector plus payload) is lumped into the distal rod BP at its tip (a point mass
has no rotary inertia, so riding on either rod is the same). Motors at A and D drive the joints
``phi`` and ``psi`` with unit gear; rotor inertia becomes joint ``armature``, viscous friction
joint ``damping`` and Coulomb friction joint ``frictionloss`` (MuJoCo's dry friction, a stiff
soft constraint: its regularisation differs from dextar's ``tanh`` only below the
regularisation speed). Units are those of the robot and inertia given: SI (m, kg, s) for a
model MuJoCo users expect (``dextar export mjcf`` writes SI unless ``--units paper``).

With a start state the model holds a keyframe ``start``: the motion's first sample with the
loop closed and the motion's velocities. Load it with::

    m = mujoco.MjModel.from_xml_path("dextar.xml")
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("start").id)

Joint order in ``qpos``: ``phi, theta1, psi, theta2``, where ``theta1`` and ``theta2`` are the
distal rods' angles relative to their proximal rods.

A proximal rod's counterweight (:attr:`dextar.dynamics.Inertia.counterweights`) is a body of
its own, welded to its rod (a child body without a joint) at its distance behind the motor
axis, with its mass and inertia and a sphere to see it: MuJoCo combines the two, so the
export checks the folding of :meth:`dextar.dynamics.Rod.with_counterweight` independently.
"""

from __future__ import annotations

import numpy as np

from .._arrays import Array
from ..dynamics.exact import Model
from ..dynamics.inertia import Counterweight
from ..errors import DextarError
from ..kinematics import direct_kinematics, elbows, task_velocity

#: Constraint softness: as stiff as MuJoCo allows (impedance 0.9999).
SOLREF = "0.0005 1"
SOLIMP = "0.9999 0.9999 0.001 0.5 2"
#: Softness of the joints' dry friction (``frictionloss``): stiff, like the closure.
SOLREF_FRICTION = "0.0005 1"


def _fmt(*values: float) -> str:
    return " ".join(f"{v:.17g}" for v in values)


def _comment(text: str) -> str:
    """``text`` safe inside an XML comment (no ``--``)."""
    return text.replace("--", "- -")


def _inertial(mass: float, com: float, izz: float) -> str:
    # a planar rod along local x: principal inertias (tiny, izz, izz) keep MuJoCo's
    # triangle inequality; MuJoCo needs strictly positive values
    m = max(mass, 1e-12)
    i = max(izz, 1e-15)
    return (f'<inertial pos="{_fmt(com, 0, 0)}" mass="{m:.17g}" '
            f'diaginertia="{_fmt(1e-3 * i, i, i)}"/>')


def to_mjcf(model: Model, *, name: str = "dextar",
            start: tuple[Array, Array] | None = None,
            units: str = "the units of the model given") -> str:
    """The MJCF text of ``model``: geometry, inertia, gravity, rotor inertia, viscous and
    Coulomb friction, and, given ``start = (q0, dq0)`` (each (2,)), a keyframe ``start`` with
    the loop closed at that state; ``units`` names the model's units in the file's comment
    (pass an SI model for MuJoCo's usual units)."""
    r, ine = model.robot, model.inertia
    p1, p2 = ine.proximal
    cws: tuple[Counterweight | None, Counterweight | None] = (None, None)
    if ine.has_counterweights:
        try:  # the rods apart from their counterweights
            p1, p2 = ine.bare_proximal
            cws = ine.counterweights
        except DextarError:  # rods that do not hold their record: the folded rods, exact
            p1, p2 = ine.proximal
    d1, d2 = ine.distal
    mP = ine.point_mass
    # distal rod BP with the point mass at its tip
    m13 = d1.mass + mP
    c13 = (d1.mass * d1.com + mP * r.L1) / m13 if m13 > 0 else 0.0
    i13 = d1.inertia + d1.mass * (d1.com - c13) ** 2 + mP * (r.L1 - c13) ** 2
    gx, gy = ine.gravity
    rad = 0.02 * min(r.l1, r.l2)
    leg = []
    for k, (pivot, prox, l, L, mass_d, com_d, inert_d) in enumerate((
            (r.A, p1, r.l1, r.L1, m13, c13, i13),
            (r.D, p2, r.l2, r.L2, d2.mass, d2.com, d2.inertia)), start=1):
        joint = "phi" if k == 1 else "psi"
        cw = cws[k - 1]
        weight = "" if cw is None or cw.none else f"""
      <body name="counterweight{k}" pos="{_fmt(-cw.distance, 0, 0)}">
        <inertial pos="0 0 0" mass="{cw.mass:.17g}" diaginertia="{_fmt(*(max(cw.inertia, 1e-15),) * 3)}"/>
        <geom type="sphere" size="{2.5 * rad:.6g}" mass="0" contype="0" conaffinity="0"/>
      </body>"""
        leg.append(f"""    <body name="proximal{k}" pos="{_fmt(pivot[0], pivot[1], 0)}">
      <joint name="{joint}" type="hinge" axis="0 0 1" armature="{ine.rotor[k - 1]:.17g}" damping="{ine.viscous[k - 1]:.17g}" frictionloss="{ine.coulomb[k - 1]:.17g}" solreffriction="{SOLREF_FRICTION}"/>
      {_inertial(prox.mass, prox.com, prox.inertia)}
      <geom type="capsule" fromto="0 0 0 {l:.17g} 0 0" size="{rad:.6g}" mass="0" contype="0" conaffinity="0"/>{weight}
      <body name="distal{k}" pos="{l:.17g} 0 0">
        <joint name="theta{k}" type="hinge" axis="0 0 1"/>
        {_inertial(mass_d, com_d, inert_d)}
        <geom type="capsule" fromto="0 0 0 {L:.17g} 0 0" size="{rad:.6g}" mass="0" contype="0" conaffinity="0"/>
        <site name="tip{k}" pos="{L:.17g} 0 0"/>
      </body>
    </body>""")
    legs = "\n".join(leg)
    key = ""
    if start is not None:
        qpos, qvel = mujoco_state(model, np.asarray(start[0], float)[None],
                                  np.asarray(start[1], float)[None])
        key = (f'  <keyframe>\n    <key name="start" qpos="{_fmt(*qpos[0])}" '
               f'qvel="{_fmt(*qvel[0])}"/>\n  </keyframe>\n')
    return f"""<mujoco model="{name}">
  <!-- five-bar exported by dextar; {_comment(units)} -->
  <compiler angle="radian"/>
  <option gravity="{_fmt(gx, gy, 0)}" timestep="0.0001" integrator="RK4">
    <flag contact="disable"/>
  </option>
  <worldbody>
{legs}
  </worldbody>
  <equality>
    <connect name="closure" site1="tip1" site2="tip2" solref="{SOLREF}" solimp="{SOLIMP}"/>
  </equality>
  <actuator>
    <motor name="motor_A" joint="phi" gear="1"/>
    <motor name="motor_D" joint="psi" gear="1"/>
  </actuator>
{key}</mujoco>
"""


def mujoco_state(model: Model, q: Array, dq: Array) -> tuple[Array, Array]:
    """``qpos`` and ``qvel`` (each (n, 4)) of the MuJoCo model for actuator states ``q, dq``
    (n, 2)."""
    r = model.robot
    q, dq = np.atleast_2d(q), np.atleast_2d(dq)
    P = direct_kinematics(r, q, model.assembly)
    B, C = elbows(r, q)
    dP = task_velocity(r, q, P, dq, tol=0.0)
    u, v = P - B, P - C
    th3 = np.arctan2(u[:, 1], u[:, 0])
    th4 = np.arctan2(v[:, 1], v[:, 0])
    dB = r.l1 * dq[:, :1] * np.stack([-np.sin(q[:, 0]), np.cos(q[:, 0])], -1)
    dC = r.l2 * dq[:, 1:] * np.stack([-np.sin(q[:, 1]), np.cos(q[:, 1])], -1)
    w3 = (u[:, 0] * (dP - dB)[:, 1] - u[:, 1] * (dP - dB)[:, 0]) / r.L1**2
    w4 = (v[:, 0] * (dP - dC)[:, 1] - v[:, 1] * (dP - dC)[:, 0]) / r.L2**2
    qpos = np.stack([q[:, 0], th3 - q[:, 0], q[:, 1], th4 - q[:, 1]], -1)
    qvel = np.stack([dq[:, 0], w3 - dq[:, 0], dq[:, 1], w4 - dq[:, 1]], -1)
    return qpos, qvel
