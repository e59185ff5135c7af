"""Where the data shipped with the software lives: parameter sets, vehicles, scenarios."""

from __future__ import annotations

from pathlib import Path

#: The project's root folder (the source tree).
ROOT = Path(__file__).resolve().parent.parent
#: Named bushing parameter sets (``models/bushings/<name>.yaml``).
PARAMETER_SET_DIR = ROOT / "models" / "bushings"
#: Vehicle definitions (``models/vehicles/``).
VEHICLE_DIR = ROOT / "models" / "vehicles"
#: The built-in default vehicle.
DEFAULT_VEHICLE = VEHICLE_DIR / "c_segment.yaml"
#: Rig scenarios (``scenarios/``) and the K&C campaign of the virtual rig (``scenarios/kc/``).
SCENARIO_DIR = ROOT / "scenarios"
KC_SCENARIO_DIR = SCENARIO_DIR / "kc"
