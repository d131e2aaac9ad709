"""What the atlas keeps of an optimization (``biped.records.atlas_optimum``): one record, its
numbers with their units, written and read back to the same bytes and the same optimum."""

import dataclasses
import json

import numpy as np
import pytest

import biped
from biped.model import units
from biped.model.criteria import ALL_CRITERIA, CRITERION_UNITS
from biped.optimization.optimize import checked, optimize
from biped.optimization.problem import GaitProblem
from biped.records.atlas_optimum import AtlasOptimum


@pytest.fixture(scope="module")
def optimum():
    model = biped.Biped(biped.Robot.paper(), "rolling")
    return optimize(GaitProblem(model, 0.3, "energy-per-metre"), starts=1, jobs=1)


def test_a_record_reads_back_to_its_bytes_and_its_optimum(optimum, tmp_path):
    """Written and read back, a record is the same record, its file the same bytes, and its
    variables and report give the same optimum again (JSON keeps every bit)."""
    record = AtlasOptimum.from_optimum(optimum, 1.5)
    path = tmp_path / "final.json"
    path.write_text(record.to_json())
    again = AtlasOptimum.read(path)
    assert again == record and again.to_json() == path.read_text()
    assert again.certified == optimum.certified and again.solved
    assert again.value == optimum.value == again.costs["energy-per-metre"]
    assert again.costs["energy-per-metre"] == pytest.approx(
        again.costs["energy"] / again.step_length, rel=1e-12
    )
    problem = GaitProblem(biped.Biped(biped.Robot.paper(), "rolling"), 0.3, "energy-per-metre")
    same = checked(problem, np.array(again.variables), again.report)
    assert same.value == optimum.value and same.feasible == optimum.feasible


def test_every_number_of_the_file_has_its_unit(optimum):
    """The declared units cover every number of the file: the criterion's for the value, each
    criterion's for the costs, the solver's variables' by name, seconds and metres."""
    content = AtlasOptimum.from_optimum(optimum, 1.5).to_dict()
    declared = AtlasOptimum.units("energy-per-metre", 1)
    texts = [f.name for f in dataclasses.fields(AtlasOptimum) if f.metadata["unit"] is None]
    texts.remove("variables")  # declared by the family (``units``)
    assert texts == ["status", "feasible", "certified", "single_start", "violations"]
    assert units.missing(content, declared) == ["single_start"]  # a text, here null
    assert declared["value"] == CRITERION_UNITS["energy-per-metre"] == "J/m"
    assert {f"costs.{c}" for c in ALL_CRITERIA} <= set(declared)
    assert declared["period"] == "s" and declared["step_length"] == "m"
    assert len(declared["variables"]) == len(content["variables"]) == 21
    assert declared["variables"][-1] == "s"  # the period, the family's last variable
    assert all(units.is_unit(u) for u in declared.values() if isinstance(u, str))


def test_a_value_that_is_not_finite_is_null_and_a_record_without_variables_starts_nothing(
    optimum,
):
    """A value or variable that is not finite is written null and read as None; such a
    record is not a start for another solve."""
    record = AtlasOptimum.from_optimum(optimum, 1.5)
    broken = dataclasses.replace(record, value=None, variables=(None, *record.variables[1:]))
    content = json.loads(broken.to_json())
    assert content["value"] is None and content["variables"][0] is None
    again = AtlasOptimum.from_dict(content)
    assert again == broken and not again.solved


def test_a_file_lacking_a_field_is_refused_naming_it(optimum, tmp_path):
    """A record lacking a field, or with one of another type, is refused naming it, and the
    file reads as missing (the stage runs again)."""
    content = AtlasOptimum.from_optimum(optimum, 1.5).to_dict()
    del content["next_optimum"]
    with pytest.raises(biped.BipedError, match="lacks next_optimum"):
        AtlasOptimum.from_dict(content)
    path = tmp_path / "own.json"
    path.write_text(json.dumps(content))
    assert AtlasOptimum.read(path) is None
    content = {**AtlasOptimum.from_optimum(optimum, 1.5).to_dict(), "costs": [1.0]}
    with pytest.raises(biped.BipedError, match="atlas optimum"):
        AtlasOptimum.from_dict(content)
