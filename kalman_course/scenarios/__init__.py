"""Scénarios de démonstration du cours : un module par exemple, données reproductibles (graines fixées)."""

from .voltage import (
    TRUE_VOLTAGE,
    VOLTAGE_NOISE_STD,
    VOLTAGE_SEED,
    constant_voltage_measurements,
    constant_voltage_model,
)

__all__ = [
    "TRUE_VOLTAGE",
    "VOLTAGE_NOISE_STD",
    "VOLTAGE_SEED",
    "constant_voltage_measurements",
    "constant_voltage_model",
]
