"""Training precision: auto picks bf16 only on a CPU with native bf16, a bf16 minibatch's loss
and gradients are close to fp32's on the same batch while the weights, gradients and heads stay
fp32, prediction is fp32 whatever the run's precision, and a run records and keeps its
precision across --resume."""
import copy

import pytest
import torch as th
import yaml

from patrolsb3.core import parse_map
from patrolsb3.runs import RunFolder
from patrolsb3.sb3 import make_vec_env, precision as precision_module
from patrolsb3.sb3.maskable_recurrent_ppo import MaskableRecurrentPPO
from patrolsb3.sb3.policy import PatrolRecurrentPolicy, policy_kwargs_for
from patrolsb3.sb3.precision import cpu_info, resolve_precision
from patrolsb3.sb3.train import train

th.set_num_threads(1)
ROOM = parse_map("S.....\n......\n......\n......", name="room")


def test_auto_is_bf16_only_on_a_cpu_with_native_bf16(monkeypatch):
    monkeypatch.setattr(precision_module, "cpu_info", lambda: {"name": "x", "native_bf16": True, "bf16_flags": []})
    assert resolve_precision("auto", "cpu") == "bf16"
    assert resolve_precision("auto", "cuda") == "fp32"
    monkeypatch.setattr(precision_module, "cpu_info", lambda: {"name": "x", "native_bf16": False, "bf16_flags": []})
    assert resolve_precision("auto", "cpu") == "fp32"
    assert resolve_precision("bf16", "cpu") == "bf16" and resolve_precision("fp32", "cpu") == "fp32"
    with pytest.raises(ValueError, match="precision must be one of auto, fp32, bf16, got 'fp16'"):
        resolve_precision("fp16")


def test_cpu_info_names_the_cpu():
    info = cpu_info()
    assert isinstance(info["name"], str) and info["name"]
    assert info["native_bf16"] == bool(info["bf16_flags"])


def _model(seed=0):
    env = make_vec_env(ROOM, agents=(1, 2, 3, 3), variant="rl-msg", seed=seed, max_agents=3, episode_steps=8)
    model = MaskableRecurrentPPO(PatrolRecurrentPolicy, env, n_steps=16, batch_size=10_000, n_epochs=1, seed=seed,
                                 device="cpu", policy_kwargs=policy_kwargs_for(env.layout, dense_sizes=(512, 341, 227)))
    _, callback = model._setup_learn(model.n_steps * model.n_envs, None)
    assert model.collect_rollouts(model.env, callback, model.rollout_buffer, model.n_steps)
    with th.no_grad():                                   # ratios != 1: the policy loss has weight
        for p in model.policy.parameters():
            p.add_(0.003 * th.randn_like(p))
    return model


def _loss_and_grads(model, data, precision):
    model.policy.precision = precision
    model.policy.optimizer.zero_grad()
    loss, terms = model.minibatch_loss(data, clip_range=0.15)
    loss.backward()
    return loss, terms, [p.grad.detach().clone() for p in model.policy.parameters()]


def test_a_bf16_minibatch_has_the_loss_and_gradients_of_fp32():
    """The paper's network (527 -> 512 -> 341 -> 227, LSTM 128) on one fixed batch of a
    rollout: bf16's loss terms within 2 % of fp32's, each parameter's gradient at cosine > 0.98
    with fp32's and the same norm within 5 %; weights, gradients and loss stay fp32."""
    model = _model()
    data = next(model.rollout_buffer.get(None))
    loss32, terms32, grads32 = _loss_and_grads(model, data, "fp32")
    loss16, terms16, grads16 = _loss_and_grads(model, data, "bf16")
    assert loss16.dtype == th.float32 and all(g.dtype == th.float32 for g in grads16)
    assert all(p.dtype == th.float32 for p in model.policy.parameters())
    assert abs(terms32["policy_loss"]) > 1e-4
    for key in ("value_loss", "entropy_loss"):
        assert terms16[key] == pytest.approx(terms32[key], rel=0.02), key
    assert terms16["policy_loss"] == pytest.approx(terms32["policy_loss"], rel=0.1, abs=2e-3)
    assert loss16.item() != loss32.item()                 # bf16 really ran
    for g16, g32 in zip(grads16, grads32):
        if g32.norm() < 1e-8:
            continue
        cosine = th.nn.functional.cosine_similarity(g16.flatten(), g32.flatten(), dim=0).item()
        assert cosine > 0.98
        assert g16.norm().item() == pytest.approx(g32.norm().item(), rel=0.05)


def test_prediction_is_fp32_whatever_the_run_trained_with():
    model = _model()
    obs = model.rollout_buffer.observations[0]
    masks = model.rollout_buffer.action_masks[0]
    seen = []
    inner = model.policy._predict
    model.policy._predict = lambda *a, **k: (seen.append(model.policy.precision), inner(*a, **k))[1]
    model.policy.precision = "fp32"
    fp32_actions, fp32_state = model.predict(obs, deterministic=True, action_masks=masks)
    model.policy.precision = "bf16"
    bf16_actions, bf16_state = model.predict(obs, deterministic=True, action_masks=masks)
    assert seen == ["fp32", "fp32"] and model.policy.precision == "bf16"
    assert (fp32_actions == bf16_actions).all()
    assert (fp32_state[0] == bf16_state[0]).all()        # bit for bit: no autocast in predict


def test_the_rollout_runs_in_the_runs_precision():
    model = _model()
    dtypes = []
    dense = model.policy.pi_features_extractor.dense
    dense.register_forward_hook(lambda module, inputs, output: dtypes.append(output.dtype))
    model.policy.precision = "bf16"
    _, callback = model._setup_learn(model.n_steps * model.n_envs, None)
    model.collect_rollouts(model.env, callback, model.rollout_buffer, 2)
    assert set(dtypes) == {th.bfloat16}
    assert model.rollout_buffer.values.dtype.name == "float32"


def tiny_hp(**extra):
    return {"n_steps": 10, "n_minibatches": 2, "eval_freq": 0, "checkpoint_freq": 400,
            "env": {"episode_steps": 5}, "policy_kwargs": {"dense_sizes": [32, 32], "lstm_hidden_size": 16},
            **extra}


def test_a_run_records_its_precision_and_resume_keeps_it(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(precision_module, "cpu_info", lambda: {"name": "x", "native_bf16": True, "bf16_flags": []})
    run = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(precision="bf16"), progress_bar=False)
    assert RunFolder(run).read_config()["hyperparams"]["precision"] == "bf16"
    train(map=ROOM, timesteps=800, out=tmp_path, hyperparams=tiny_hp(precision="fp32"), resume=True,
          progress_bar=False)
    assert "keeps the precision it was trained with (bf16), not fp32" in capsys.readouterr().err
    # a run from before the setting (no precision in its config.yml) resumes in fp32
    config = RunFolder(run).config_file
    saved = yaml.safe_load(config.read_text())
    del saved["hyperparams"]["precision"]
    config.write_text(yaml.safe_dump(saved))
    train(map=ROOM, timesteps=1200, out=tmp_path, hyperparams=tiny_hp(precision="bf16"), resume=True,
          progress_bar=False)
    assert "keeps the precision it was trained with (fp32), not bf16" in capsys.readouterr().err


def test_a_bf16_run_resumed_without_native_bf16_goes_on_in_fp32_and_says_from_when(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(precision_module, "cpu_info", lambda: {"name": "x", "native_bf16": True, "bf16_flags": []})
    run = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(precision="auto"), progress_bar=False)
    assert RunFolder(run).read_config()["hyperparams"]["precision"] == "bf16"
    monkeypatch.setattr(precision_module, "cpu_info", lambda: {"name": "y", "native_bf16": False, "bf16_flags": []})
    train(map=ROOM, timesteps=800, out=tmp_path, hyperparams=tiny_hp(precision="auto"), resume=True, progress_bar=False)
    assert "was trained in bf16 so far and goes on in fp32: this machine has no native bf16" in capsys.readouterr().err
    changes = RunFolder(run).read_config()["precision_changes"]
    assert [(c["timesteps"], c["precision"]) for c in changes] == [(400, "fp32")]
    # resumed again here: it is an fp32 run now, nothing more to record
    train(map=ROOM, timesteps=1200, out=tmp_path, hyperparams=tiny_hp(precision="auto"), resume=True, progress_bar=False)
    assert "goes on in" not in capsys.readouterr().err
    assert len(RunFolder(run).read_config()["precision_changes"]) == 1
    # bf16 asked for explicitly keeps bf16, emulated or not, and says what that costs
    train(map=ROOM, timesteps=400, out=tmp_path / "explicit", hyperparams=tiny_hp(precision="bf16"), progress_bar=False)
    assert "this CPU has no native bf16, so torch emulates it" in capsys.readouterr().err
    assert precision_module.resumed_precision("bf16", "bf16") == ("bf16", "")


def test_a_run_that_went_on_in_fp32_for_want_of_native_bf16_goes_back_to_bf16_where_it_is_native(
        tmp_path, capsys, monkeypatch):
    native = {"name": "x", "native_bf16": True, "bf16_flags": ["avx512_bf16"]}
    monkeypatch.setattr(precision_module, "cpu_info", lambda: native)
    run = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(precision="auto"), progress_bar=False)
    monkeypatch.setattr(precision_module, "cpu_info", lambda: {**native, "native_bf16": False, "bf16_flags": []})
    train(map=ROOM, timesteps=800, out=tmp_path, hyperparams=tiny_hp(precision="auto"), resume=True, progress_bar=False)
    monkeypatch.setattr(precision_module, "cpu_info", lambda: native)       # a machine with native bf16 again
    capsys.readouterr()
    train(map=ROOM, timesteps=1200, out=tmp_path, hyperparams=tiny_hp(precision="fp32"), resume=True,
          progress_bar=False)                                                # fp32 asked for: stays fp32
    assert "goes on in" not in capsys.readouterr().err
    train(map=ROOM, timesteps=1600, out=tmp_path, hyperparams=tiny_hp(precision="auto"), resume=True, progress_bar=False)
    assert "was trained in fp32 so far and goes on in bf16: this machine has native bf16" in capsys.readouterr().err
    changes = RunFolder(run).read_config()["precision_changes"]
    assert [(c["timesteps"], c["precision"]) for c in changes] == [(400, "fp32"), (1200, "bf16")]
    # a run that started in fp32 stays fp32 on any machine
    assert precision_module.resumed_precision("fp32", "auto", started="fp32") == ("fp32", "")
    assert precision_module.resumed_precision("fp32", "auto", started="bf16")[0] == "bf16"
    assert precision_module.resumed_precision("fp32", "auto") == ("fp32", "")
    # a resume from a checkpoint before the change drops it (the stretch after it is gone)
    RunFolder(run).cut_back_to(400)
    assert RunFolder(run).read_config()["precision_changes"] == []


def test_a_bad_precision_is_refused_before_a_run_folder_exists(tmp_path):
    with pytest.raises(ValueError, match="precision must be one of auto, fp32, bf16, got 'half'"):
        train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(precision="half"), progress_bar=False)
    assert not any(tmp_path.iterdir())


def test_a_bf16_checkpoint_loads_and_acts_as_fp32(tmp_path):
    run = train(map=ROOM, timesteps=400, out=tmp_path, hyperparams=tiny_hp(precision="bf16"), progress_bar=False)
    model = MaskableRecurrentPPO.load(RunFolder(run).model_file, device="cpu")
    assert model.policy.precision == "fp32"
    assert all(p.dtype == th.float32 for p in copy.deepcopy(model.policy).parameters())
