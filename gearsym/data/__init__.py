"""Measured time series (issue 5, first layer): tidy CSV files read and checked against a model
(:mod:`.measurements`), and synthetic measurements simulated from a model with noise (:mod:`.simulate`)."""
from .measurements import (DataError, Measurements, Record, Window, load_measurements,
                           MIN_PERIODS, MIN_SAMPLES_PER_PERIOD, SPACING_TOLERANCE)
from .simulate import MeasurementTable, simulate_measurements, steps_for, write_measurements

__all__ = ["DataError", "MIN_PERIODS", "MIN_SAMPLES_PER_PERIOD", "MeasurementTable", "Measurements", "Record",
           "SPACING_TOLERANCE", "Window", "load_measurements", "simulate_measurements", "steps_for",
           "write_measurements"]
