"""Every Python recipe on the environments page runs as written, with only its training budget
cut (each cut must match the page once, so a changed recipe fails here rather than running
long or untested). Each runs as its own script (Tianshou's workers re-import it) in a fresh
directory; recipes of a library that is not installed are skipped."""
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "environments.md"

#: the budget cuts, by a line that identifies the recipe: (text on the page, text run)
CUTS = {
    "from tianshou.algorithm import PPO": [
        ("max_epochs=10, epoch_num_steps=20_000", "max_epochs=1, epoch_num_steps=200"),
        ("collection_step_num_env_steps=2048", "collection_step_num_env_steps=200"),
        ("VectorReplayBuffer(2048,", "VectorReplayBuffer(200,")],
    "from skrl.agents.torch.ppo import PPO": [
        ('cfg={"timesteps": 20_000,', 'cfg={"timesteps": 40, "disable_progressbar": True,'),
        ("PPO_CFG(rollouts=256,", "PPO_CFG(rollouts=16,"),
        ("RandomMemory(memory_size=256,", "RandomMemory(memory_size=16,")],
    "PPO(\"MlpPolicy\", venv).learn(100_000)": [
        ('PPO("MlpPolicy", venv).learn(100_000)', 'PPO("MlpPolicy", venv, n_steps=8).learn(128)')],
    "env.rollout(max_steps=1000)": [("max_steps=1000", "max_steps=50")],
}
#: a recipe needs these modules (skipped without them)
NEEDS = {"tianshou": "tianshou", "skrl": "skrl", "torchrl": "torchrl",
         "RecordVideo": "moviepy", "stable_baselines3": "stable_baselines3"}


def recipes() -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", PAGE.read_text(), flags=re.S | re.M)


def test_the_page_has_the_recipes_this_file_cuts():
    blocks = recipes()
    assert len(blocks) >= 7
    for key in CUTS:
        assert sum(key in b for b in blocks) == 1, key


@pytest.mark.parametrize("i", range(len(recipes())))
def test_each_recipe_on_the_environments_page_runs(i, tmp_path):
    code = recipes()[i]
    for word, module in NEEDS.items():
        if word in code:
            pytest.importorskip(module)
    for key, cuts in CUTS.items():
        if key in code:
            for page_text, run_text in cuts:
                assert code.count(page_text) == 1, page_text
                code = code.replace(page_text, run_text)
    script = tmp_path / "recipe.py"
    script.write_text(code)
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                          text=True, timeout=600, env={**__import__("os").environ,
                                                       "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr[-3000:]
    if "RecordVideo" in code:
        assert list((tmp_path / "videos").glob("*.mp4"))
