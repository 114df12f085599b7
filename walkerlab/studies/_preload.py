"""Imported once in the forkserver process: builds the model functions so workers start warm."""

from walkerlab.studies.points import warm_up

warm_up()
