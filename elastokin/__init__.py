"""elastokin: full-vehicle transient simulation with hysteretic, viscoelastic rubber bushings, on MuJoCo.

The front door (the names below are loaded when first used, so that ``import elastokin`` stays
light and the command line starts without MuJoCo)::

    import elastokin
    run = elastokin.Simulation("c_segment", "pumping").run(progress=True)
    run["camber_fl"], run.units["camber_fl"]            # NumPy, SI: rad
    run.metrics()[1]["front"]["bump_camber_deg_per_m"]   # a K&C metric of case 1
    figures = run.plot()                                 # matplotlib figures
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from elastokin.core.provenance import software_version

if TYPE_CHECKING:
    from elastokin.api.built_ins import built_ins, copy_built_in, dataset
    from elastokin.api.diagnosis import diagnose
    from elastokin.api.kernels import compile_kernels
    from elastokin.api.verdicts import Diagnosis
    from elastokin.api.runs import Run, load_run
    from elastokin.api.scenarios import load_scenario, scenario_from
    from elastokin.api.simulation import Simulation
    from elastokin.api.sweeps import sweep
    from elastokin.api.vehicles import Vehicle, load_vehicle
    from elastokin.bushings import BushingBank, ParameterSet, load_parameter_set

__version__ = software_version()

#: Each name of the API and the module that defines it.
_API = {
    "Simulation": "elastokin.api.simulation",
    "Run": "elastokin.api.runs", "load_run": "elastokin.api.runs",
    "Vehicle": "elastokin.api.vehicles", "load_vehicle": "elastokin.api.vehicles",
    "load_scenario": "elastokin.api.scenarios", "scenario_from": "elastokin.api.scenarios",
    "Diagnosis": "elastokin.api.verdicts", "diagnose": "elastokin.api.diagnosis",
    "sweep": "elastokin.api.sweeps",
    "compile_kernels": "elastokin.api.kernels",
    "built_ins": "elastokin.api.built_ins", "copy_built_in": "elastokin.api.built_ins", "dataset": "elastokin.api.built_ins",
    "BushingBank": "elastokin.bushings", "ParameterSet": "elastokin.bushings", "load_parameter_set": "elastokin.bushings",
}
__all__ = ["__version__", *_API]


def __getattr__(name: str) -> Any:
    """The API's names, imported when first asked for."""
    if name not in _API:
        raise AttributeError(f"module 'elastokin' has no attribute {name!r}")
    value = getattr(importlib.import_module(_API[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_API))
