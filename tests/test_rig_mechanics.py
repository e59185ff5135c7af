"""The K&C rig's own mechanics (issue 53 item 1): its floating pads' friction and compliance and its
body clamp's compliance, each held to its closed form on the default car with linear bushings
(whose responses are linear in the loads), and a rig scenario's or a truth's ``rig`` mapping read
in its units, refused with file, key and value when wrong."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from elastokin.core.errors import InputError
from elastokin.diagnosis.virtual_kc_rig import parse_kc_truth
from elastokin.vehicle.model.definition import CORNERS, SIDE_SIGN
from elastokin.vehicle.model.elements import BuildOptions, RigMechanics
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.rig_file import KEYS, rig_values
from elastokin.vehicle.scenarios.scenario_file import parse_scenario
from elastokin.vehicle.simulation.rig import KCRig

PUMPING = Path(__file__).resolve().parents[1] / "scenarios" / "kc" / "pumping.yaml"


@pytest.fixture(scope="module")
def vehicle():
    return load_vehicle()


def loaded(vehicle, mechanics: RigMechanics, fy: float, fx=(0.0, 0.0, 0.0, 0.0), settle_s: float = 1.5) -> KCRig:
    """The car with linear bushings on a rig of ``mechanics``, settled, then ``fy`` [N] on every pad
    and ``fx`` [N] on each, settled."""
    rig = KCRig(vehicle, BuildOptions(bushing_model="linear", rig_mechanics=mechanics))
    rig.settle(0.5)
    rig.set_pad_loads(fx=fx, fy=[fy] * 4)
    rig.settle(settle_s)
    return rig


def centres_y(rig: KCRig) -> np.ndarray:
    return np.array([rig.measure().wheels[c].wheel_centre[1] for c in CORNERS])


def contacts(rig: KCRig) -> np.ndarray:
    """(4, 2) each contact point's (x, y) [m]: its pad's carriage's."""
    rig.measure()
    return rig.data.xpos[rig.carriage_body, :2].copy()


def test_the_body_clamp_takes_the_pads_lateral_load_and_the_wheels_move_with_the_body(vehicle):
    """A lateral clamp compliance c: the body and every wheel centre move by c × ΣFy (the suspension's
    deflection under the same loads unchanged), to 1 %."""
    compliance, fy = 0.02e-6, 3000.0   # 0.02 mm/kN, 3 kN a pad
    rigid = centres_y(loaded(vehicle, RigMechanics(), fy))
    yielding = loaded(vehicle, RigMechanics(clamp_lateral_m_per_n=compliance), fy)
    expected = compliance * 4 * fy    # 0.24 mm
    assert centres_y(yielding) - rigid == pytest.approx([expected] * 4, rel=0.01)
    chassis = yielding.model.body("chassis").id
    assert yielding.data.xpos[chassis][1] == pytest.approx(expected, rel=0.01)


def test_the_clamp_rolls_by_its_compliance_times_the_pads_moment(vehicle):
    """A roll clamp compliance c: the body turns about x by c × the moment about the clamp's axis (through
    the body's centre of mass) of the forces the pads put into the car (commanded Fy, measured Fz), to 1 %."""
    compliance = math.radians(0.005) * 1e-3   # 0.005 deg/(kN·m)
    rig = loaded(vehicle, RigMechanics(clamp_roll_rad_per_nm=compliance), 3000.0)
    out = rig.measure()
    cg = np.asarray(vehicle.body.cg)
    moment = 0.0
    for corner in CORNERS:
        contact = rig.data.site_xpos[rig.model.site(rig.car.corners[corner]["contact_site"]).id]
        force = out.wheels[corner].pad_force
        moment += np.cross(contact - cg, force)[0]
    roll = rig.data.qpos[rig.model.jnt_qposadr[rig.model.joint("clamp_hinge_x").id]]
    assert roll == pytest.approx(compliance * moment, rel=0.01)
    assert abs(moment) > 4e3   # the lateral forces' lever over the ground: a real moment


def friction_forces(rig: KCRig) -> np.ndarray:
    """(4,) the force of each pad's bearing friction on its carriage in y [N] (MuJoCo's friction rows)."""
    m, d = rig.model, rig.data
    out = np.zeros(4)
    for k, corner in enumerate(CORNERS):
        dof = m.jnt_dofadr[m.joint(f"pad_y_{corner}").id]
        rows = (d.efc_type[:d.nefc] == mujoco.mjtConstraint.mjCNSTR_FRICTION_DOF) & (d.efc_id[:d.nefc] == dof)
        out[k] = d.efc_force[:d.nefc][rows].sum()
    return out


def test_the_pads_friction_holds_back_the_lateral_force_by_itself(vehicle):
    """Pads with friction F under a lateral force Fy rising on every pad: each slides, its bearing
    holding back F (to 0.1 %); Fy held, then falling back: each slides the other way, F the other way;
    at rest, stuck, the contact patches do not creep (to 10 nm in a second)."""
    friction, fy = 40.0, 1500.0
    rig = KCRig(vehicle, BuildOptions(bushing_model="linear", rig_mechanics=RigMechanics(pad_friction_n=friction)))
    rig.settle(0.5)
    rig.ramp(1.0, fy=([0.0] * 4, [fy] * 4))
    rising = friction_forces(rig)
    rig.settle(0.5)
    before = contacts(rig)
    rig.settle(1.0)
    assert np.abs(contacts(rig) - before).max() < 1e-8   # 0.2 mm/s before MuJoCo's no-slip pass
    rig.ramp(1.0, fy=([fy] * 4, [fy - 3 * friction] * 4))
    falling = friction_forces(rig)
    assert rising == pytest.approx([-friction] * 4, rel=1e-3)
    assert falling == pytest.approx([friction] * 4, rel=1e-3)


def test_a_pad_held_by_its_friction_holds_the_contact_patch_through_its_compliance(vehicle):
    """A pad whose friction is not overcome holds its contact patch through its own compliance c_p
    (x and y alike) in parallel with the suspension's at the contact patch (C, 2 × 2 in x and y,
    from the frictionless rig's responses to Fy on every pad and to Fx as the held pads push back,
    the left and right sides opposite): under Fy the patch moves by (C⁻¹ + I/c_p)⁻¹ (0, Fy), to 1 %."""
    force, pad = 400.0, 2e-6    # N, 2 mm/kN
    at_rest = contacts(loaded(vehicle, RigMechanics(), 0.0))
    sides = np.array([SIDE_SIGN[c] for c in CORNERS])
    along_x = (contacts(loaded(vehicle, RigMechanics(), 0.0, force * sides)) - at_rest) / (force * sides[:, None])
    along_y = (contacts(loaded(vehicle, RigMechanics(), force)) - at_rest) / force
    stuck = RigMechanics(pad_friction_n=1000.0, pad_compliance_m_per_n=pad)
    held = contacts(loaded(vehicle, stuck, force)) - contacts(loaded(vehicle, stuck, 0.0))
    for k in range(4):
        suspension = np.column_stack([along_x[k], along_y[k]])
        expected = np.linalg.solve(np.linalg.inv(suspension) + np.eye(2) / pad, [0.0, force])
        assert held[k] == pytest.approx(expected, rel=0.01, abs=0.01 * abs(expected[1]))
        assert abs(held[k, 1]) < 0.9 * abs(along_y[k, 1] * force)   # the pad takes a real share


def test_a_rig_mapping_is_read_in_its_units_and_refused_when_wrong():
    """A rig scenario's ``rig`` keys in N, mm/kN and deg/(kN·m), SI inside, written back as given;
    errors name the file, its line, the key and the value."""
    text = PUMPING.read_text()
    given = {"pad_friction_n": 12.0, "pad_compliance_mm_per_kn": 3.0, "clamp_lateral_mm_per_kn": 0.01,
             "clamp_roll_deg_per_knm": 0.004}
    body = "".join(f"  {k}: {v}\n" for k, v in given.items())
    scenario = parse_scenario(text + "rig:\n" + body, PUMPING)
    assert scenario.rig.clamp_lateral_m_per_n == pytest.approx(1e-8)
    assert scenario.rig.clamp_roll_rad_per_nm == pytest.approx(math.radians(0.004) / 1e3)
    assert rig_values(scenario.rig) == pytest.approx(given)
    assert parse_scenario(text, PUMPING).rig.ideal
    lines = len(text.splitlines())
    for bad, expected in ((" pad_friction_n: -3", "non-negative"), (" pad_fricton_n: 3", "unknown key 'pad_fricton_n'"),
                          (" clamp_roll_deg_per_knm: 5", "at most 1 deg/(kN·m)"),
                          (" pad_friction_n: .nan", "finite number"),
                          (" pad_compliance_mm_per_kn: 3", "in series with the pads' friction")):
        with pytest.raises(InputError) as caught:
            parse_scenario(text + "rig:\n " + bad + "\n", PUMPING)
        assert f"pumping.yaml:{lines + 2}" in str(caught.value) and expected in str(caught.value), caught.value
    with pytest.raises(InputError, match=r"truth.yaml: rig.clamp_lateral_mm_per_kn: expected at most 1 mm/kN"):
        parse_kc_truth({"level": "kc", "rig": {"clamp_lateral_mm_per_kn": 2}}, "truth.yaml")
    assert sorted(name for name, *_ in KEYS.values()) == sorted(RigMechanics.__dataclass_fields__)   # one key each
