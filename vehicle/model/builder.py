"""Build the MuJoCo model of a vehicle definition with ``mujoco.MjSpec``.

Topology (per side; the right side mirrors the left):

* front pseudo-McPherson: the lower wishbone hangs from the body on its first bushing (E1 front:
  six joints, 3 slide + 3 hinge in the bushing's frame); every further bushing of the wishbone
  (E2 front) is a light sleeve on six joints of its own, welded to the wishbone. The knuckle sits
  on the wishbone through a ball joint; the strut rod slides in the tube on the knuckle along the
  strut axis (spring, damper and the rod's Coulomb friction, MuJoCo's ``frictionloss``, on that
  slide) and is tied to the body at the top mount by a ``connect``. The rack slides laterally in
  the body; each tie rod is a spatial tendon of fixed length (``equality/tendon``). The wheel
  turns on a hinge of the knuckle.
* rear twist beam: each trailing arm hangs from the body on its E1 rear bushing; the left arm
  carries the beam centre on a hinge about the beam axis (torsional stiffness of the beam),
  welded to the right arm. Springs and dampers are spatial tendons between arm and body.
* K&C rig (``rig=True``): under each wheel a pad slides vertically (driven by an
  ``equality/joint``) and carries a carriage free in x and y, tied to the wheel's contact point
  by a ``connect``; wheel hinges are locked (brakes on); the rack position is driven.
* road (``road=True``): the body free, the wheels spinning on their hinges, the rack position
  driven (the steering), a ground plane to look at; the tyres' forces come from
  :mod:`elastokin.vehicle.simulation.road` (MuJoCo's contacts stay off).

Linear bushing directions live in the joints' ``stiffness``/``damping`` (implicit under
``integrator="discrete"``); the others (and any law with effects) get a reference stiffness in the
joint and the rest of their force from :mod:`elastokin.vehicle.simulation.coupling`, as do the bushings' cross
stiffnesses. The right side's laws, effects and cross stiffnesses are the mirror images of the
left's (:func:`mirror_signs`).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field, replace

import mujoco
import numpy as np

from elastokin.bushings.effects import NO_EFFECTS
from elastokin.vehicle.model.definition import DIRECTIONS, SIDES, BushingDef, Spring, VehicleDefinition
from elastokin.vehicle.model.elements import BuildOptions, Channel, CrossTerm, Element, joint_stiffness
from elastokin.vehicle.model.geometry import (contact_point, frame_from, mirror, mirror_axes, mirror_signs, mirrored_law,
                                             wheel_axis)
from elastokin.core.errors import InputError

#: Stiffness of a "rigid" bushing translation [N/m] (kinematics mode).
RIGID_TRANSLATION = 1e9
#: Loop closures, rig drives, strut friction and brakes: impedance close to 1 and a time constant
#: [s] fixed, not MuJoCo's refsafe floor (2 h), so that they do not soften as h rises. 2 ms, the
#: floor at a 1 ms step, keeps the compliance every figure was measured with; at h = 2 ms the rear
#: camber loop is then 8.1e-5° against 7.6e-5° at h ≤ 0.5 ms (1.6e-4° with the floor), the front
#: within 0.3 %, the pumping's closure error 7.7 µm (4.4 µm at 1 ms); tools/benchmarks/vehicle_speed.py.
CLOSURE_SOLREF = (2e-3, 1.0)
CLOSURE_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
SLEEVE_MASS = 0.4          #: mass of a closed bushing's sleeve [kg], taken from its part's mass
BEAM_CENTRE_MASS = 1.0    #: share of each arm's mass carried by the beam-centre body [kg]
PAD_MASS = 1.0             #: rig pad and carriage masses [kg] (gravity compensated)
PAD_NOSLIP_ITERATIONS = 10  #: MuJoCo's no-slip passes a step when the rig's pads have friction
_NO_COLLISION = dict(contype=0, conaffinity=0)


@dataclass
class CarModel:
    """The compiled model with the names the rig and the coupling need."""

    definition: VehicleDefinition
    options: BuildOptions
    spec: mujoco.MjSpec
    model: mujoco.MjModel
    channels: list[Channel]
    elements: list[Element]
    closures: list[str]                  #: loop-closure equality names
    corners: dict[str, dict[str, str]] = field(default_factory=dict)
    cross: list[CrossTerm] = field(default_factory=list)   #: directional couplings of the bushings

    def xml(self) -> str:
        """The MJCF of the model."""
        return self.spec.to_xml()

    def copy(self) -> CarModel:
        """This car with a copy of its compiled model (what a mounting changes: drives' targets,
        flags), the rest shared: a fresh car without compiling again (its channels, elements and
        names are not changed after the build)."""
        return replace(self, model=copy.copy(self.model))

    def body_point(self, data: mujoco.MjData, point) -> np.ndarray:
        """World position [m] at ``data``'s state (its kinematics recomputed) of a point given in the
        body's design frame."""
        mujoco.mj_kinematics(self.model, data)
        chassis = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, "chassis")
        return data.xpos[chassis] + data.xmat[chassis].reshape(3, 3) @ np.asarray(point, float)


def _quat(rot: np.ndarray) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(rot).ravel())
    return q


class _Builder:
    """Creates bodies from world design poses, so every point is written in world coordinates."""

    def __init__(self, vehicle: VehicleDefinition, options: BuildOptions):
        self.v, self.o = vehicle, options
        self.spec = mujoco.MjSpec()
        self.spec.modelname = vehicle.name
        self.spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
        self.spec.compiler.autolimits = True
        opt = self.spec.option
        opt.timestep = options.timestep
        opt.integrator = mujoco.mjtIntegrator.mjINT_DISCRETE
        # no MuJoCo contacts (the road's tyres are our own); no island discovery: joints and
        # closures tie every body into one island, and searching for others cost 8 % of a rig step
        # (47.9 -> 44.2 µs with STVS on all 36 directions; results move by round-off only); no
        # refsafe floor, which would soften CLOSURE_SOLREF to 2 h
        disable = mujoco.mjtDisableBit
        opt.disableflags |= disable.mjDSBL_CONTACT | disable.mjDSBL_ISLAND | disable.mjDSBL_REFSAFE
        opt.gravity = [0.0, 0.0, -9.81]
        self.poses: dict[str, tuple[np.ndarray, np.ndarray]] = {"world": (np.zeros(3), np.eye(3))}
        self.bodies: dict[str, mujoco.MjsBody] = {"world": self.spec.worldbody}
        self.channels: list[Channel] = []
        self.elements: list[Element] = []
        self.closures: list[str] = []
        self.corners: dict[str, dict[str, str]] = {}
        self.cross: list[CrossTerm] = []

    # -- primitives --------------------------------------------------------------------------
    def local(self, body: str, p) -> np.ndarray:
        pos, rot = self.poses[body]
        return rot.T @ (np.asarray(p, float) - pos)

    def body(self, parent: str, name: str, pos, rot, mass: float, com, inertia, gravcomp: float = 0.0):
        """Add a body at world pose (pos, rot) with mass at world point ``com`` (inertia in the body axes)."""
        ppos, prot = self.poses[parent]
        b = self.bodies[parent].add_body(name=name, pos=prot.T @ (np.asarray(pos) - ppos), quat=_quat(prot.T @ rot))
        b.mass = mass
        b.ipos = rot.T @ (np.asarray(com, float) - np.asarray(pos))
        b.inertia = np.asarray(inertia, float)
        b.explicitinertial = True
        b.gravcomp = gravcomp
        self.poses[name] = (np.asarray(pos, float), np.asarray(rot, float))
        self.bodies[name] = b
        return b

    def capsule(self, body: str, a, b, radius: float = 0.012, rgba=(0.6, 0.6, 0.65, 1)):
        self.bodies[body].add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[radius, 0, 0],
                                   fromto=np.concatenate([self.local(body, a), self.local(body, b)]),
                                   rgba=rgba, **_NO_COLLISION)

    def site(self, body: str, name: str, p):
        self.bodies[body].add_site(name=name, pos=self.local(body, p), size=[0.01, 0, 0])

    def closure(self, name: str, kind, b1: str, b2: str, anchor_world=None):
        """A loop-closing ``connect`` or ``weld`` between two bodies, anchored at a world point
        (a weld defaults to body1's origin)."""
        eq = self.spec.add_equality(name=name, type=kind, objtype=mujoco.mjtObj.mjOBJ_BODY, name1=b1, name2=b2)
        data = np.zeros(12)
        data[10] = 1.0  # weld torque scale
        if kind == mujoco.mjtEq.mjEQ_CONNECT:  # anchor in body1; MuJoCo places body2's at design
            data[0:3] = self.local(b1, anchor_world)
        else:  # anchor in body2, where the load passes (else the weld's soft rotation rows carry
            # a moment and the joint turns); zero relative pose = MuJoCo takes the design one
            data[0:3] = self.local(b2, self.poses[b1][0] if anchor_world is None else anchor_world)
        eq.data = data
        self._stiff(eq)
        self.closures.append(name)
        return eq

    def _stiff(self, eq):
        eq.solref = list(CLOSURE_SOLREF)
        eq.solimp = list(CLOSURE_SOLIMP)

    def drive(self, name: str, joint: str):
        """An ``equality/joint`` holding ``joint`` at ``eq_data[0]`` (set at run time)."""
        eq = self.spec.add_equality(name=name, type=mujoco.mjtEq.mjEQ_JOINT, objtype=mujoco.mjtObj.mjOBJ_JOINT,
                                    name1=joint)
        self._stiff(eq)

    def bushing_joints(self, body: str, bushing: BushingDef, side: str, sign: float):
        """Six joints (slide x, y, z; hinge x, y, z) in the bushing frame = ``body``'s frame, and the
        bushing's cross stiffnesses; side ``sign`` (+1 left, −1 right) mirrors the left's laws."""
        b = self.bodies[body]
        name = f"{bushing.name}_{side}"
        signs = dict(zip(DIRECTIONS, mirror_signs(bushing.axes, sign)))
        for i, d in enumerate(DIRECTIONS):
            direction = bushing.directions[d]
            model = self.o.bushing_model if d in self.o.bushing_model_directions else None
            params, effects = mirrored_law(direction.channel(model), direction.effects_si(), signs[d])
            if self.o.rigid_bushings and len(d) == 1:
                params = params.replace(model="linear", K0=RIGID_TRANSLATION, C=0.0, n_cells=0,
                                        S_sup=math.inf, S_inf=-math.inf)
                effects = NO_EFFECTS
            ch = Channel(f"{name}.{d}", f"{name}_{d}", params, effects)
            axis = np.eye(3)[i % 3]
            kind = mujoco.mjtJoint.mjJNT_SLIDE if len(d) == 1 else mujoco.mjtJoint.mjJNT_HINGE
            j = b.add_joint(name=ch.joint, type=kind, axis=axis)
            j.stiffness = [joint_stiffness(ch), 0.0, 0.0]
            j.damping = [params.C, 0.0, 0.0]
            self.channels.append(ch)
        for term in bushing.coupling:
            a, c = term.directions
            self.cross.append(CrossTerm(f"{name}_{a}", f"{name}_{c}", signs[a] * signs[c] * term.stiffness))

    # -- the car -----------------------------------------------------------------------------
    def build(self) -> CarModel:
        v = self.v
        if self.o.road and (self.o.rig or self.o.clamped):
            raise ValueError("a car on the road is neither on the rig nor clamped")
        if self.o.road:
            self.spec.worldbody.add_geom(name="road", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 1],
                                         rgba=[0.45, 0.45, 0.45, 1], **_NO_COLLISION)
        chassis_rot = np.eye(3)
        chassis = self.body("world", "chassis", np.zeros(3), chassis_rot, v.body.mass, v.body.cg,
                            v.body.inertia)
        if not self.o.clamped:
            chassis.add_freejoint(name="chassis_free")
        elif self.o.rig:
            self.clamp(chassis)
        chassis.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[1.6, 0.6, 0.05],
                         pos=self.local("chassis", [v.body.cg[0], 0, 0.45]), rgba=[0.3, 0.4, 0.7, 0.3],
                         **_NO_COLLISION)
        self.rack()
        for side, sign in SIDES:
            self.front_corner(side, sign)
        for side, sign in SIDES:
            self.rear_corner(side, sign)
        self.beam()
        self.anti_roll_bar()
        try:
            model = self.spec.compile()
        except ValueError as exc:  # what the file's checks let through and MuJoCo refuses
            raise InputError(f"MuJoCo cannot build this vehicle: {exc}", source=str(v.path)) from None
        return CarModel(v, self.o, self.spec, model, self.channels, self.elements, self.closures, self.corners,
                        self.cross)

    def clamp(self, chassis):
        """The body clamp's compliant directions (:meth:`RigMechanics.clamp`): a joint each at the body's centre of mass."""
        body = self.v.body
        for kind, axis, compliance in self.o.rig_mechanics.clamp():
            i = "xyz".index(axis)
            _compliant(chassis, compliance, body.mass if kind == "slide" else body.inertia[i], pos=body.cg,
                       name=f"clamp_{kind}_{axis}", axis=np.eye(3)[i], type=getattr(mujoco.mjtJoint, f"mjJNT_{kind.upper()}"))

    def rack(self):
        f = self.v.front
        inner = np.array(f.hardpoints["tie_rod_inner"])
        centre = np.array([inner[0], 0.0, inner[2]])
        self.body("chassis", "rack", centre, np.eye(3), f.masses["rack"], centre, [0.05, 1e-3, 0.05])
        self.bodies["rack"].add_joint(name="rack", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 1, 0])
        self.capsule("rack", mirror(inner, 1), mirror(inner, -1), 0.015)
        if self.o.rig or self.o.road:
            self.drive("rack_drive", "rack")

    def front_corner(self, side: str, sign: float):
        v, f = self.v, self.v.front
        hp = {k: mirror(p, sign) for k, p in f.hardpoints.items()}
        bushings = [b for b in v.bushings if b.child == "front.wishbone"]
        wishbone = f"wishbone_{side}"
        com = (hp["wishbone_front_pivot"] + hp["wishbone_rear_pivot"] + hp["lower_ball_joint"]) / 3.0
        closing = len(bushings) - 1
        m = f.masses["wishbone"] - SLEEVE_MASS * closing
        if m <= 0:
            raise InputError(f"{f.masses['wishbone']} kg, less than the {closing} bushing sleeve(s) it carries "
                             f"({SLEEVE_MASS} kg each); expected more", source=str(v.path), key="front.masses.wishbone")
        self._hang("chassis", wishbone, bushings, side, sign, m, com, [0.05, 0.05, 0.09])
        self.capsule(wishbone, hp["wishbone_front_pivot"], hp["lower_ball_joint"])
        self.capsule(wishbone, hp["wishbone_rear_pivot"], hp["lower_ball_joint"])

        knuckle = f"knuckle_{side}"
        wc = hp["wheel_centre"]
        self.body(wishbone, knuckle, hp["lower_ball_joint"], np.eye(3), f.masses["knuckle"],
                  wc + np.array([0.0, -sign * 0.08, 0.03]), [0.25, 0.2, 0.2])
        self.bodies[knuckle].add_joint(name=f"ball_joint_{side}", type=mujoco.mjtJoint.mjJNT_BALL)
        self.capsule(knuckle, hp["lower_ball_joint"], hp["strut_lower"], 0.02)
        self.capsule(knuckle, hp["strut_lower"], wc, 0.02)
        self.capsule(knuckle, wc, hp["tie_rod_outer"], 0.012)
        self.site(knuckle, f"tie_rod_outer_{side}", hp["tie_rod_outer"])

        rod = f"strut_rod_{side}"
        axis = hp["strut_top"] - hp["strut_lower"]
        rot = frame_from(axis, np.array([1.0, 0, 0]))
        self.body(knuckle, rod, hp["strut_lower"], rot, f.masses["strut_rod"],
                  (hp["strut_lower"] + hp["strut_top"]) / 2, [0.02, 0.02, 1e-3])
        j = self.bodies[rod].add_joint(name=f"strut_{side}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 0, 1])
        j.frictionloss = f.strut_friction[0 if sign > 0 else 1]
        # friction as stiff as the loop closures: at MuJoCo's default (0.02 s) the regularised friction
        # let the rod creep through 200 N at 2 mm/s (pad-force loop 7 N wide instead of 2·200 N·MR)
        j.solref_friction, j.solimp_friction = list(CLOSURE_SOLREF), list(CLOSURE_SOLIMP)
        self.capsule(rod, hp["strut_lower"], hp["strut_top"], 0.01, (0.8, 0.8, 0.8, 1))
        self._spring_damper_joint(j, f"front_{side}", f.spring, f.damper.curve)
        self.closure(f"top_mount_{side}", mujoco.mjtEq.mjEQ_CONNECT, rod, "chassis", hp["strut_top"])

        tendon = self.spec.add_tendon(name=f"tie_rod_{side}")
        self.site("rack", f"tie_rod_inner_{side}", hp["tie_rod_inner"])
        tendon.wrap_site(f"tie_rod_inner_{side}")
        tendon.wrap_site(f"tie_rod_outer_{side}")
        eq = self.spec.add_equality(name=f"tie_rod_{side}", type=mujoco.mjtEq.mjEQ_TENDON,
                                    objtype=mujoco.mjtObj.mjOBJ_TENDON, name1=f"tie_rod_{side}")
        self._stiff(eq)
        self.closures.append(f"tie_rod_{side}")
        self.wheel(knuckle, f"front_{side}", wc, f.static_toe, f.static_camber, sign)

    def rear_corner(self, side: str, sign: float):
        v, r = self.v, self.v.rear
        hp = {k: mirror(p, sign) for k, p in r.hardpoints.items()}
        bushings = [b for b in v.bushings if b.child == "rear.arm"]
        arm = f"arm_{side}"
        wc = hp["wheel_centre"]
        beam_end = np.array([hp["beam_centre"][0], hp["arm_pivot"][1], hp["beam_centre"][2]])
        closing = len(bushings) - 1
        com = (hp["arm_pivot"] + wc + beam_end) / 3.0
        mass = r.masses["arm"] - SLEEVE_MASS * closing - BEAM_CENTRE_MASS
        if mass <= 0:
            raise InputError(f"{r.masses['arm']} kg, less than the arm's share of the beam ({BEAM_CENTRE_MASS} kg) and "
                             f"its {closing} bushing sleeve(s) ({SLEEVE_MASS} kg each); expected more",
                             source=str(v.path), key="rear.masses.arm")
        self._hang("chassis", arm, bushings, side, sign, mass, com,
                   [0.15, 0.1, 0.2])
        self.capsule(arm, hp["arm_pivot"], wc, 0.025)
        self.capsule(arm, beam_end, hp["beam_centre"], 0.03)
        hub = f"hub_{side}"
        self.body(arm, hub, wc, np.eye(3), r.masses["hub"], wc - np.array([0, sign * 0.05, 0]), [0.03, 0.04, 0.03])
        for kind in ("spring", "damper"):
            lo, up = f"rear_{kind}_lower_{side}", f"rear_{kind}_upper_{side}"
            self.site(arm, lo, hp[f"{kind}_lower"])
            self.site("chassis", up, hp[f"{kind}_upper"])
            t = self.spec.add_tendon(name=f"rear_{kind}_{side}")
            t.wrap_site(lo)
            t.wrap_site(up)
            length0 = float(np.linalg.norm(hp[f"{kind}_upper"] - hp[f"{kind}_lower"]))
            el = Element(f"rear_{kind}_{side}", "tendon", t.name, -1.0)
            if kind == "spring":
                el.spring, el.preload = r.spring, r.spring.preload or 0.0
                t.stiffness = [r.spring.rate, 0.0, 0.0]
                t.springlength = [length0 + el.preload / r.spring.rate] * 2
            else:
                el.damper_curve = r.damper.curve
            self.elements.append(el)
        self.wheel(hub, f"rear_{side}", wc, r.static_toe, r.static_camber, sign)

    def beam(self):
        """The cross beam's torsion: a hinge about the beam axis between the two arms; and, if the
        beam bends, a hinge about the car's x axis with its bending stiffness."""
        r = self.v.rear
        centre = np.array(r.hardpoints["beam_centre"])
        # the middle of the beam, taken from the arms' masses: its inertia stiffens the weld in rotation
        self.body("arm_left", "beam_centre", centre, np.eye(3), 2 * BEAM_CENTRE_MASS, centre, [0.25, 0.01, 0.25])
        j = self.bodies["beam_centre"].add_joint(name="beam_torsion", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0])
        j.stiffness = [r.beam_torsion, 0.0, 0.0]
        if r.beam_bending_stiffness is not None:
            j = self.bodies["beam_centre"].add_joint(name="beam_bending", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[1, 0, 0])
            j.stiffness = [r.beam_bending_stiffness, 0.0, 0.0]
        self.closure("beam_weld", mujoco.mjtEq.mjEQ_WELD, "beam_centre", "arm_right")

    def anti_roll_bar(self):
        """Front anti-roll bar: a fixed tendon of (left − right) strut length with a stiffness."""
        t = self.spec.add_tendon(name="front_anti_roll_bar")
        t.wrap_joint("strut_left", 1.0)
        t.wrap_joint("strut_right", -1.0)
        t.stiffness = [self.v.front.anti_roll_rate, 0.0, 0.0]
        t.springlength = [0.0, 0.0]

    def _hang(self, parent, part, bushings, side, sign, mass, com, inertia):
        """The part on its first bushing's joints; further bushings as sleeves welded to it."""
        first, *others = bushings
        axes = mirror_axes(first.axes, sign)
        self.body(parent, part, mirror(first.location, sign), axes.T, mass, com, inertia)
        self.bushing_joints(part, first, side, sign)
        for b in others:
            sleeve = f"{b.name}_{side}_sleeve"
            loc = mirror(b.location, sign)
            self.body(parent, sleeve, loc, mirror_axes(b.axes, sign).T, SLEEVE_MASS, loc, [1e-3] * 3)
            self.bushing_joints(sleeve, b, side, sign)
            self.closure(f"{b.name}_{side}_weld", mujoco.mjtEq.mjEQ_WELD, sleeve, part)

    def _spring_damper_joint(self, joint, name: str, spring: Spring, damper_curve):
        """Spring and damper on a strut slide (positive = extension, so compression = −q)."""
        preload = spring.preload or 0.0
        joint.stiffness = [spring.rate, 0.0, 0.0]
        joint.springref = preload / spring.rate
        self.elements.append(Element(f"{name}_spring", "joint", joint.name, -1.0, spring, preload))
        self.elements.append(Element(f"{name}_damper", "joint", joint.name, -1.0, damper_curve=damper_curve))

    def wheel(self, parent: str, corner: str, centre, toe: float, camber: float, sign: float):
        """Wheel on a spin hinge; on the rig, a pad under its contact point."""
        t = self.v.tyre
        spin_left = sign * wheel_axis(toe, camber, sign)  # spin axis pointing to the vehicle's left
        rot = frame_from(spin_left, np.array([1.0, 0, 0]), order="yx")
        name = f"wheel_{corner}"
        i_spin, i_diam = t.wheel_inertia
        self.body(parent, name, centre, rot, t.wheel_mass, centre, [i_diam, i_spin, i_diam])
        hinge = self.bodies[name].add_joint(name=f"spin_{corner}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0])
        if self.o.road:  # the brake is the hinge's dry friction, as stiff as the closures (the default creeps)
            hinge.solref_friction, hinge.solimp_friction = list(CLOSURE_SOLREF), list(CLOSURE_SOLIMP)
        self.bodies[name].add_geom(type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[t.radius, 0.095, 0],
                                   quat=_quat(frame_from(np.array([0, 1.0, 0]), np.array([1.0, 0, 0]))),
                                   rgba=[0.1, 0.1, 0.1, 0.6], **_NO_COLLISION)
        contact = contact_point(centre, toe, camber, sign, t.radius)
        self.site(name, f"contact_{corner}", contact)
        self.site(name, f"centre_{corner}", centre)
        names = {"wheel": name, "contact_site": f"contact_{corner}", "centre_site": f"centre_{corner}"}
        if self.o.rig:
            self.drive(f"brake_{corner}", hinge.name)
            pad = f"pad_{corner}"
            self.body("world", pad, contact, np.eye(3), PAD_MASS, contact, [0.01] * 3, gravcomp=1.0)
            self.bodies[pad].add_joint(name=f"pad_z_{corner}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 0, 1])
            self.bodies[pad].add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.2, 0.15, 0.01],
                                      pos=[0, 0, -0.012], rgba=[0.7, 0.5, 0.2, 1], **_NO_COLLISION)
            carriage = f"carriage_{corner}"
            self.body(self.pad_float(pad, corner, contact), carriage, contact, np.eye(3), PAD_MASS, contact, [0.01] * 3,
                      gravcomp=1.0)
            for axis, direction in (("x", [1, 0, 0]), ("y", [0, 1, 0])):
                j = self.bodies[carriage].add_joint(name=f"pad_{axis}_{corner}", type=mujoco.mjtJoint.mjJNT_SLIDE,
                                                    axis=direction)
                if self.o.rig_mechanics.pad_friction_n > 0.0:
                    j.frictionloss = self.o.rig_mechanics.pad_friction_n
                    j.solref_friction, j.solimp_friction = list(CLOSURE_SOLREF), list(CLOSURE_SOLIMP)
                    # MuJoCo's solver lets a stuck friction creep (a pad holding 300 N, 0.2 mm/s): no-slip holds it
                    self.spec.option.noslip_iterations = PAD_NOSLIP_ITERATIONS
            self.drive(f"pad_drive_{corner}", f"pad_z_{corner}")
            self.closure(f"contact_{corner}", mujoco.mjtEq.mjEQ_CONNECT, name, carriage, contact)
            names |= {"pad_drive": f"pad_drive_{corner}", "pad_z": f"pad_z_{corner}", "contact_eq": f"contact_{corner}"}
        self.corners[corner] = names


    def pad_float(self, pad: str, corner: str, contact) -> str:
        """The body the pad's carriage floats on: the pad itself, or, for a compliant pad, its top plate
        on x and y springs (:attr:`RigMechanics.pad_compliance_m_per_n`), the friction acting through them."""
        compliance = self.o.rig_mechanics.pad_compliance_m_per_n
        if compliance == 0.0:
            return pad
        top = f"pad_top_{corner}"
        self.body(pad, top, contact, np.eye(3), PAD_MASS, contact, [0.01] * 3, gravcomp=1.0)
        for axis, direction in (("x", [1, 0, 0]), ("y", [0, 1, 0])):
            _compliant(self.bodies[top], compliance, PAD_MASS, name=f"pad_top_{axis}_{corner}",
                       type=mujoco.mjtJoint.mjJNT_SLIDE, axis=direction)
        return top


def _compliant(body, compliance: float, inertia: float, **joint) -> None:
    """A joint (its MjSpec attributes ``joint``) on ``body`` with a spring of ``compliance`` [m/N, rad/(N·m)],
    critically damped on ``inertia`` alone [kg, kg·m²]: a rig's stiff part, its lag (c/k) a few ms."""
    j = body.add_joint(**joint)
    j.stiffness = [1.0 / compliance, 0.0, 0.0]
    j.damping = [2.0 * math.sqrt(inertia / compliance), 0.0, 0.0]


def build(vehicle: VehicleDefinition, options: BuildOptions = BuildOptions()) -> CarModel:
    """Compile the MuJoCo model of ``vehicle`` (spring preloads must be resolved, see ``elastokin.vehicle.model.statics``)."""
    return _Builder(vehicle, options).build()
