"""Force models (one module each) behind one interface (solver/forces/base.py).

`MODELS` is the explicit registry: name -> "module:Class". A model is imported and computed only
when something selects it (model only what a scene needs).
"""
from __future__ import annotations

import importlib

MODELS: dict[str, str] = {
    "momentum_exchange": "feelflow.solver.forces.momentum_exchange:GalileanMomentumExchange",
    "momentum_exchange_classic": "feelflow.solver.forces.momentum_exchange:ClassicMomentumExchange",
    "macroscopic": "feelflow.solver.forces.macroscopic:MacroscopicDrag",
    "pressure": "feelflow.solver.forces.pressure:PressureIntegration",
}


class UnknownForceModel(ValueError):
    pass


def create_model(name: str, **options):
    """Instantiate a force model by registry name."""
    if name not in MODELS:
        raise UnknownForceModel(f"unknown force model {name!r}; choose from {', '.join(MODELS)}")
    module_name, cls_name = MODELS[name].split(":")
    return getattr(importlib.import_module(module_name), cls_name)(**options)
