"""Measured time series (issue 5, first layer): tidy CSV files read and checked against a model
(:mod:`.measurements`: the file format and :func:`load_measurements`, one step per file below it —
:mod:`.csvtext` reads the text, :mod:`.layout` says what each column is, :mod:`.grouping` parses the rows into
records, :mod:`.rules` checks each record; :mod:`.record` and :mod:`.dataset` are the types, :mod:`.channels`
what a column measures), and synthetic measurements simulated from a model with noise (:mod:`.simulate`)."""
from .channels import channel_expression, channel_symbols
from .dataset import Measurements
from .errors import DataError
from .measurements import load_measurements
from .record import Record, Window
from .rules import MIN_PERIODS, MIN_SAMPLES_PER_PERIOD, SPACING_TOLERANCE
from .simulate import MeasurementTable, simulate_measurements, steps_for, write_measurements

__all__ = ["DataError", "MIN_PERIODS", "MIN_SAMPLES_PER_PERIOD", "MeasurementTable", "Measurements", "Record",
           "SPACING_TOLERANCE", "Window", "channel_expression", "channel_symbols", "load_measurements",
           "simulate_measurements", "steps_for", "write_measurements"]
