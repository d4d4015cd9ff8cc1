"""TOML scenarios: the two-mass format of 0.1 (:mod:`.two_mass`: ``[system]``,
``[contact]``) and the 0.2 format of any system (:mod:`.system`: ``[structure]``), read,
checked (errors name the file, the section and the key) and run as the command line
does; SI units throughout."""

from vibroimpact.scenario.two_mass import Scenario, ScenarioError, load_scenario, parse_scenario

__all__ = ["Scenario", "ScenarioError", "load_scenario", "parse_scenario"]
