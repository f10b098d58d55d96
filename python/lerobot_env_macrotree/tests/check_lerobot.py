"""``lerobot-eval`` on the plugin, for real: LeRobot finds the plugin by its distribution name,
builds the ``macrotree`` env type, and reports the environment's success as ``pc_success``.

torch is too heavy for CI, so this is not a pytest module: ``tests/system/python_package.rs``
runs it when ``MACROTREE_LEROBOT_PYTHON`` names a Python with lerobot 0.6 (it installs the
macrotree wheel and the plugin there first). By hand: ``python
python/lerobot_env_macrotree/tests/check_lerobot.py [WORK_DIR]``.

The policy is a LeRobot ACT checkpoint (small, untrained) whose action head is zeroed: it emits
exactly 0, so in the ``residual`` action mode the task's own tree drives the arm. ``lerobot-eval``
must then report every episode a success when the episode is long enough for the tree (500
frames, 10 s) and none when it is not (50 frames, 1 s).
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import torch
from lerobot.configs import FeatureType, NormalizationMode
from lerobot.envs.configs import EnvConfig
from lerobot.envs.factory import make_env_config
from lerobot.envs.utils import NEW_ROLLOUT_OPTION, env_to_policy_features
from lerobot.policies.act.configuration_act import ACTConfig
from lerobot.policies.act.modeling_act import ACTPolicy
from lerobot.policies.factory import make_pre_post_processors

import lerobot_env_macrotree as plugin
from lerobot_env_macrotree.facts import LEROBOT_RESET_OPTION

EPISODES = 2


def discovered_by_distribution_name() -> None:
    """A fresh interpreter, as ``lerobot-eval`` starts: LeRobot's plugin discovery alone (no
    import of the plugin by name) registers the ``macrotree`` env type."""
    code = (
        "from lerobot.utils.import_utils import register_third_party_plugins\n"
        "from lerobot.envs.configs import EnvConfig\n"
        "before = 'macrotree' in EnvConfig.get_known_choices()\n"
        "register_third_party_plugins()\n"
        "print(before, 'macrotree' in EnvConfig.get_known_choices())\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.split() == ["False", "True"], out
    print("register_third_party_plugins() registers env type 'macrotree': passed")


def config_matches_the_plugins_facts() -> EnvConfig:
    """The registered config: its gym id, kwargs and features are the plugin's facts."""
    assert NEW_ROLLOUT_OPTION == LEROBOT_RESET_OPTION, NEW_ROLLOUT_OPTION
    cfg = make_env_config("macrotree", action_mode="residual", cameras=["wrist"], image_height=48)
    assert cfg.gym_id == plugin.gym_id("CubeToBowl-v0"), cfg.gym_id
    assert cfg.gym_kwargs == plugin.gym_kwargs(
        action_mode="residual", cameras=["wrist"], image_size=(48, 320)
    )
    features = env_to_policy_features(cfg)
    assert features["observation.images.wrist"].shape == (3, 48, 320), features
    assert features["observation.state"].type is FeatureType.STATE
    assert features["observation.environment_state"].shape == (14,), features
    assert features["action"].shape == (7,), features
    print("EnvConfig 'macrotree': gym id, kwargs and features match the plugin: passed")
    return cfg


def zero_action_checkpoint(folder: Path) -> Path:
    """A LeRobot ACT checkpoint on the plugin's state features whose actions are exactly 0."""
    cfg = make_env_config("macrotree", action_mode="residual")
    features = env_to_policy_features(cfg)
    policy_cfg = ACTConfig(
        device="cpu",
        chunk_size=10,
        n_action_steps=10,
        dim_model=32,
        n_heads=2,
        dim_feedforward=64,
        n_encoder_layers=1,
        n_decoder_layers=1,
        use_vae=False,
        input_features={k: f for k, f in features.items() if f.type is not FeatureType.ACTION},
        output_features={"action": features["action"]},
        normalization_mapping={
            "STATE": NormalizationMode.MEAN_STD,
            "ENV": NormalizationMode.MEAN_STD,
            "ACTION": NormalizationMode.MEAN_STD,
        },
    )
    policy = ACTPolicy(policy_cfg)
    with torch.no_grad():
        policy.model.action_head.weight.zero_()
        policy.model.action_head.bias.zero_()
    stats: dict[str, dict[str, Any]] = {
        key: {"mean": torch.zeros(f.shape), "std": torch.ones(f.shape)}
        for key, f in features.items()
    }
    pre, post = make_pre_post_processors(policy_cfg, dataset_stats=stats)
    out = folder / "zero_act"
    policy.save_pretrained(out)
    pre.save_pretrained(out)
    post.save_pretrained(out)
    return out


def lerobot_eval(policy: Path, output: Path, episode_length: int) -> dict[str, Any]:
    """Runs ``lerobot-eval`` on the plugin; its overall metrics."""
    command = [
        str(Path(sys.executable).parent / "lerobot-eval"),
        f"--policy.path={policy}",
        "--policy.device=cpu",
        "--env.type=macrotree",
        "--env.action_mode=residual",
        f"--env.episode_length={episode_length}",
        f"--eval.n_episodes={EPISODES}",
        f"--eval.batch_size={EPISODES}",
        f"--output_dir={output}",
    ]
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True)
    wall = time.perf_counter() - start
    assert done.returncode == 0, f"{command}\n{done.stdout}\n{done.stderr}"
    overall: dict[str, Any] = json.loads((output / "eval_info.json").read_text())["overall"]
    print(
        f"$ lerobot-eval --policy.path=zero_act --env.type=macrotree --env.action_mode=residual "
        f"--env.episode_length={episode_length} --eval.n_episodes={EPISODES} "
        f"--eval.batch_size={EPISODES}: pc_success {overall['pc_success']}, "
        f"avg_max_reward {overall['avg_max_reward']}, n_episodes {overall['n_episodes']}, "
        f"videos {len(overall['video_paths'])}, {wall:.1f} s wall"
    )
    return overall


def main() -> None:
    import lerobot

    print(f"lerobot {lerobot.__version__}, torch {torch.__version__}")
    discovered_by_distribution_name()
    config_matches_the_plugins_facts()
    work = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp())
    policy = zero_action_checkpoint(work)
    long = lerobot_eval(policy, work / "eval_500", 500)
    assert long["n_episodes"] == EPISODES and long["pc_success"] == 100.0, long
    print("the task tree's episodes, 500 frames: every one a success: passed")
    short = lerobot_eval(policy, work / "eval_50", 50)
    assert short["n_episodes"] == EPISODES and short["pc_success"] == 0.0, short
    print("the same episodes cut at 50 frames: none a success: passed")


if __name__ == "__main__":
    main()
