"""Flythroughs as output: the endoscope that renders frames, the video writer, the saved flight, the flight planned
from two points, and its scores against a ground truth."""
