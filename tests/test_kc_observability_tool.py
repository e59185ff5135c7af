"""tools/kc_observability.py's floor through a rig's errors (the magnitudes kc_catalogue.THROUGH_A_RIG
holds come from it): interpolated in the effect's coordinate where the excess crosses MIN_EXCESS for
good, in proportion below the first magnitude tried, none where the last is below."""

import importlib.util
import math
from pathlib import Path

import pytest

from elastokin.diagnosis.kc_catalogue import MIN_EXCESS

_spec = importlib.util.spec_from_file_location("kc_observability",
                                               Path(__file__).resolve().parents[1] / "tools" / "kc_observability.py")
tool = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(tool)


def test_the_floor_through_a_rig_crosses_min_excess_in_the_effects_coordinate():
    # a factor (spring rate): its effect is its logarithm; the excess there 0.2, 0.6, 1.4, 2.0 × MIN_EXCESS
    m = tool.magnitudes("spring_rate")
    assert m[0] == pytest.approx(1.05) and m[-1] == pytest.approx(1.4) and len(m) == tool.THROUGH_RIG_STEPS
    logs = [math.log(x) for x in m]
    assert logs[2] - logs[1] == pytest.approx(logs[1] - logs[0])   # even in the effect's coordinate
    pairs = list(zip(m, [0.2 * MIN_EXCESS, 0.6 * MIN_EXCESS, 1.4 * MIN_EXCESS, 2.0 * MIN_EXCESS]))
    assert tool.rig_floor("spring_rate", pairs) == pytest.approx(math.exp(0.5 * (logs[1] + logs[2])))
    # above it from the first: in proportion to the effect (an excess of 2 at ×1.05 is 1 at ×√1.05)
    assert tool.rig_floor("spring_rate", [(x, 2.0 * MIN_EXCESS) for x in m]) == pytest.approx(math.sqrt(1.05))
    # dipping below after the first: from where it stays above; below at the top: never
    dip = list(zip(m, [1.2 * MIN_EXCESS, 0.8 * MIN_EXCESS, 1.2 * MIN_EXCESS, 2.0 * MIN_EXCESS]))
    assert tool.rig_floor("spring_rate", dip) == pytest.approx(math.exp(0.5 * (logs[1] + logs[2])))
    assert tool.rig_floor("spring_rate", list(zip(m, [0.1, 0.3, 0.5, 0.9 * MIN_EXCESS]))) == math.inf
    # a length (a hardpoint's offset [mm]): its effect is the value itself
    excess = [0.25 * MIN_EXCESS, 0.75 * MIN_EXCESS, 1.25 * MIN_EXCESS, 2.0 * MIN_EXCESS]
    pairs = list(zip(tool.magnitudes("hardpoint"), excess))
    assert tool.rig_floor("hardpoint", pairs) == pytest.approx(2.5)   # between 2 and 3 mm, halfway
