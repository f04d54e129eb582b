"""The model registry: one table serves the builder, load_model and CLI help; lazy imports; old model files.

Independent checks: the constructor signatures of the classes (inspect), hand-written model files in
the layout fogdrift wrote before the models moved into ``fogdrift.models`` (format version 1), AR
predictions by hand, and fresh interpreters (subprocess) for what gets imported.
"""

from __future__ import annotations

import inspect
import json
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

import fogdrift.models as models
from fogdrift.errors import ConfigError, ModelFileError
from fogdrift.models import (MODEL_NAMES, MODELS, DriftModel, build_model, describe_models, load_model, model_spec,
                             save_model)
from fogdrift.pipeline import AnalysisConfig


def test_names_order_and_uniqueness():
    known = ["grey-elman", "elman", "gm11", "ar", "persistence"]  # report order (new rows may be added)
    assert [name for name in MODEL_NAMES if name in known] == known
    assert len({s.cls for s in MODELS}) == len(MODELS)
    assert all(s.name == s.name.lower().strip() for s in MODELS)


@pytest.mark.parametrize("spec", MODELS, ids=lambda s: s.name)
def test_each_row_matches_its_class(spec):
    cls = spec.load()
    assert issubclass(cls, DriftModel) and cls.__name__ == spec.cls
    assert cls.label == spec.label
    assert spec.description and "\n" not in spec.description
    params = set(inspect.signature(cls.__init__).parameters) - {"self"}
    assert {k for k, _ in spec.settings} <= params
    assert {k for k, _ in spec.fixed} <= params
    assert set(spec.inputs) <= params
    assert ("progress" in spec.inputs) == ("progress" in params)  # a model that reports progress declares it
    assert all(hasattr(AnalysisConfig(), attr) for _, attr in spec.settings)
    assert getattr(models, spec.cls) is cls  # lazy package attribute


def test_build_model_from_analysis_settings():
    cfg = AnalysisConfig(lags=3, hidden=5, epochs=7, seed=2, activation="logsig", training="bp", gm_window=10)

    def progress(*args):
        pass

    got = {name: build_model(name, cfg, progress=progress) for name in MODEL_NAMES}
    for name in ("grey-elman", "elman"):
        p = got[name].get_params()
        assert (p["lags"], p["hidden"], p["epochs"], p["seed"], p["activation"], p["training"]) == (
            3, 5, 7, 2, "logsig", "bp")
        assert p["progress"] is progress
    assert type(got["grey-elman"]).__name__ == "GreyElman" and type(got["elman"]).__name__ == "Elman"
    assert got["gm11"].get_params() == {"mode": "rolling", "window": 10, "shift": "auto", "shift_margin": 1.0}
    assert got["ar"].get_params() == {"order": 3, "max_order": 12}
    assert got["persistence"].get_params() == {}
    # a mapping works as settings; None gives the class defaults (plus the fixed keywords)
    assert build_model("ar", {"lags": 6}).order == 6
    assert build_model("gm11").get_params()["window"] == 8


def test_pipeline_uses_the_registry():
    import fogdrift.pipeline as pipeline

    assert pipeline.MODEL_NAMES is MODEL_NAMES
    assert pipeline.make_model is build_model
    assert AnalysisConfig().models == MODEL_NAMES


def test_names_are_case_insensitive_and_unknown_names_are_errors():
    assert model_spec(" GM11 ").name == "gm11"
    assert type(build_model("Persistence")).__name__ == "Persistence"
    for bad in ("lstm", "", "gm-11", None, 3):
        with pytest.raises(ConfigError) as info:
            build_model(bad, AnalysisConfig())
        msg = str(info.value)
        assert all(name in msg for name in MODEL_NAMES), msg
        assert "models=" in msg and "--models" in info.value.render({"models": "--models"})
    with pytest.raises(ConfigError, match="gm_window"):
        build_model("gm11", SimpleNamespace(lags=3))


def test_describe_models_lists_every_row_in_order():
    lines = describe_models().splitlines()
    assert [line.split(":")[0] for line in lines] == list(MODEL_NAMES)


def test_removed_alias_modules_are_gone_and_unknown_attributes_raise():
    # fogdrift.grey and fogdrift.baselines were compatibility aliases of fogdrift.models.grey / .ar;
    # nothing imported them any more, so they were removed (issue 8), as was fogdrift.elman.
    import importlib.util

    assert importlib.util.find_spec("fogdrift.grey") is None
    assert importlib.util.find_spec("fogdrift.baselines") is None
    assert importlib.util.find_spec("fogdrift.elman") is None
    with pytest.raises(AttributeError):
        models.NoSuchModel  # noqa: B018


# -- model files ------------------------------------------------------------------------------------
def _write(base, doc, arrays):
    base.with_suffix(".json").write_text(json.dumps(doc, indent=2))
    np.savez(base.with_suffix(".npz"), **arrays)


def test_files_written_before_the_move_still_load(tmp_path):
    """Format version 1 as fogdrift wrote it when the classes lived in fogdrift.baselines / fogdrift.grey /
    fogdrift.models: the file names only the class, so the move changes nothing."""
    head = {"format": "fogdrift-model", "format_version": 1}
    _write(tmp_path / "ar", {**head, "class": "AR", "params": {"order": 2, "max_order": 12},
                             "state": {"order_": 2, "intercept_": 0.1, "sigma_": 0.01, "n_train_": 100}},
           {"coef_": np.array([0.5, 0.25]), "aic_": np.empty(0), "last_": np.array([1.0, 2.0])})
    _write(tmp_path / "pers", {**head, "class": "Persistence", "params": {}, "state": {"last_": 0.15}}, {})
    _write(tmp_path / "gm", {**head, "class": "GM11",
                             "params": {"mode": "whole", "window": 8, "shift": 0.0, "shift_margin": 1.0},
                             "state": {"shift_": 0.0, "a_": 0.0, "b_": 0.3, "x0_first_": 0.25, "n_train_": 10,
                                       "C_": 0.2, "P_": 1.0, "grade_": "good", "mre_pct_": 1.0,
                                       "class_ratio_pass_": True}},
           {"last_window_": np.array([0.3, 0.3, 0.3, 0.3])})
    ar = load_model(tmp_path / "ar")
    assert type(ar).__module__ == "fogdrift.models.ar"
    # by hand: 0.1 + 0.5 * y[k-1] + 0.25 * y[k-2]
    assert ar.forecast(2).tolist() == pytest.approx([0.1 + 0.5 * 2.0 + 0.25 * 1.0, 0.1 + 0.5 * 1.35 + 0.25 * 2.0])
    assert ar.predict(np.array([3.0]), history=np.array([1.0, 2.0])).tolist() == pytest.approx([1.35])
    assert load_model(tmp_path / "pers").forecast(2).tolist() == [0.15, 0.15]
    # a = 0: the GM(1,1) time response is the constant b
    assert load_model(tmp_path / "gm").forecast(3).tolist() == pytest.approx([0.3, 0.3, 0.3])
    _write(tmp_path / "odd", {**head, "class": "LSTM", "params": {}, "state": {}}, {})
    with pytest.raises(ModelFileError, match="unknown model class 'LSTM'.*GM11"):
        load_model(tmp_path / "odd")


def _imports_after(code: str) -> set:
    """Modules a fresh interpreter has imported after running ``code`` (printed as JSON)."""
    script = code + "\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))\n"
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True, timeout=300)
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


def test_loading_linear_models_does_not_import_jax(tmp_path):
    """GM(1,1), AR and persistence files load (and predict) without JAX; a grey-Elman file does import it,
    which shows the check can fail."""
    from fogdrift.models.ar import AR
    from fogdrift.models.grey import GM11
    from fogdrift.models.persistence import Persistence

    y = np.sin(0.05 * np.arange(300)) + 2.0
    paths = []
    for name, model in (("gm", GM11()), ("ar", AR(order=3)), ("pers", Persistence())):
        save_model(model.fit(y[:200]), tmp_path / name)
        paths.append(str(tmp_path / name))
    code = ("import numpy as np\nfrom fogdrift.models import load_model, build_model\n"
            f"for p in {paths!r}:\n    m = load_model(p)\n    m.predict(np.ones(20) * 2.0, history=np.ones(20))\n"
            "for n in ('gm11', 'ar', 'persistence'):\n    build_model(n)\n")
    mods = _imports_after(code)
    assert "jax" not in mods and "fogdrift.models.elman" not in mods and "fogdrift.models.training" not in mods
    assert {"fogdrift.models.grey", "fogdrift.models.ar"} <= mods

    pytest.importorskip("jax")
    from fogdrift.models.elman import GreyElman

    save_model(GreyElman(hidden=2, epochs=2, window=32).fit(y[:200]), tmp_path / "ge")
    assert "jax" in _imports_after(f"from fogdrift.models import load_model\nload_model({str(tmp_path / 'ge')!r})")


def test_importing_the_package_and_the_pipeline_imports_no_model_module():
    mods = _imports_after("import fogdrift.models, fogdrift.pipeline\nfogdrift.models.MODEL_NAMES")
    assert "jax" not in mods
    assert not {"fogdrift.models.grey", "fogdrift.models.ar", "fogdrift.models.elman"} & mods


# ---- hyper-parameters declared once (ModelParam rows): CLI, settings, build, rule ---------------------------------
@pytest.mark.parametrize("spec", [s for s in MODELS if s.params], ids=lambda s: s.name)
def test_every_declared_parameter_is_a_constructor_keyword_with_a_default(spec):
    sig = inspect.signature(spec.load().__init__).parameters
    for p in spec.params:
        assert p.name in sig and sig[p.name].default is not inspect.Parameter.empty, (spec.name, p.name)
        assert p.kind in (int, float, str) and p.help


def test_a_declared_parameter_goes_from_the_command_line_to_the_model():
    from fogdrift.models import check_model_params, parse_model_params

    mp = parse_model_params(["GM11.shift_margin=2", "elman.patience=7"])
    assert mp == {"gm11": {"shift_margin": 2.0}, "elman": {"patience": 7}}
    assert isinstance(mp["gm11"]["shift_margin"], float) and isinstance(mp["elman"]["patience"], int)
    cfg = AnalysisConfig(models=("gm11", "elman"), model_params=mp).validate()
    assert build_model("gm11", cfg).shift_margin == 2.0 and build_model("elman", cfg).patience == 7
    assert build_model("gm11", AnalysisConfig()).shift_margin == 1.0  # not set: the constructor's default
    assert cfg.to_dict()["model_params"] == mp and "model_params" not in AnalysisConfig().to_dict()
    assert check_model_params({"gm11": {"shift_margin": 3}}) == {"gm11": {"shift_margin": 3.0}}  # int as float


@pytest.mark.parametrize("given, words", [
    (["gm11.shift_margin=-1"], "GM11 shift_margin must be a finite number >= 0"),  # the model's own rule
    (["elman.patience=0"], "patience must be an integer >= 1"),
    (["gm11.shift_margin=abc"], "expected a number"),
    (["gm11.window=3"], "declares no such parameter; settable: "),
    (["gm11shift_margin=2"], "expected MODEL.NAME=VALUE"),
    (["lstm.hidden=2"], "unknown drift model 'lstm'"),
])
def test_a_bad_declared_parameter_is_refused_before_any_data_with_its_flag(given, words):
    from fogdrift.cli._app import FLAGS
    from fogdrift.errors import render_options
    from fogdrift.models import parse_model_params

    with pytest.raises(ConfigError) as ei:
        AnalysisConfig(model_params=parse_model_params(given)).validate()
    assert words in str(ei.value) and "\n" not in str(ei.value)
    shown = render_options(ei.value.args[0], FLAGS)  # what the CLI prints
    assert shown.startswith("--param ") or "--models" in shown


def test_a_parameter_of_a_model_not_run_is_refused():
    with pytest.raises(ConfigError, match=r"gm11\.shift_margin is set but gm11 is not among the models run"):
        AnalysisConfig(models=("ar",), model_params={"gm11": {"shift_margin": 2.0}}).validate()


def test_a_recurrent_network_too_large_for_the_memory_budget_is_refused_before_any_work(monkeypatch):
    """``--hidden 100000`` under a memory budget made JAX fail allocating 40 GB with a traceback (issue 36): the
    weights need h^2 + h n_in + 2 h + 1 float32 values x 6 copies while training (by hand below); the config
    refuses it in one line naming --hidden and the budget, only where a recurrent model is asked for."""
    from fogdrift.models.registry import RECURRENT_WEIGHT_COPIES, recurrent_memory_need
    from fogdrift.pipeline import AnalysisConfig

    assert RECURRENT_WEIGHT_COPIES == 6
    assert recurrent_memory_need(100_000, 8) == 4 * 6 * (10**10 + 800_000 + 200_000 + 1)
    monkeypatch.setenv("FOGDRIFT_MAX_MEMORY", "2G")
    with pytest.raises(ConfigError, match=r"hidden= 100000: .* 224 GiB .* 2 GiB \(FOGDRIFT_MAX_MEMORY\)"):
        AnalysisConfig(models=("elman",), hidden=100_000).validate()
    AnalysisConfig(models=("ar",), hidden=100_000).validate()  # no network: nothing to refuse
    AnalysisConfig(models=("elman",), hidden=64).validate()
    monkeypatch.setenv("FOGDRIFT_MAX_MEMORY", "0")  # no budget
    AnalysisConfig(models=("elman",), hidden=100_000).validate()


def test_declared_inputs_reach_only_the_models_that_declare_them():
    """The Kalman row declares ``dt_s`` (it works in seconds) and reads ``noise_method`` from the settings, the
    Elman rows declare ``progress``; a model whose row declares no input is built without them (an undeclared
    keyword would be a TypeError)."""
    from fogdrift.models.registry import build_model, model_spec

    assert model_spec("kalman").inputs == ("dt_s",) and model_spec("ar").inputs == ()
    k = build_model("kalman", {"noise_method": "gmwm"}, inputs={"dt_s": 0.5, "unused": 1})
    assert k.get_params()["dt_s"] == 0.5 and k.get_params()["noise_method"] == "gmwm"
    assert build_model("ar", {"lags": 3}, inputs={"dt_s": 0.5}).get_params()["order"] == 3
    # the progress callback reaches the rows that declare it, and only them, from either argument
    def report(*args):
        pass

    assert model_spec("elman").inputs == ("progress",)
    assert build_model("elman", inputs={"progress": report}).progress is report
    assert build_model("elman", progress=report).progress is report
    assert build_model("kalman", progress=report, inputs={"dt_s": 0.5}).get_params()["dt_s"] == 0.5
