"""Manoeuvring models and their simulation: term algebra, models, integrators, steering machine."""
