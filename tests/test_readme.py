"""The README opens with the two commands a fresh machine runs; CI runs exactly those."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_ci_runs_the_readme_commands_verbatim():
    readme = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```bash\n(.*?)\n```", readme, flags=re.S)
    main_job, tests = blocks[0].strip(), blocks[1].strip()
    assert "rotordrop drop" in main_job and "pytest" in tests
    assert "\n" not in main_job and "\n" not in tests          # one line each
    ci = [line.strip() for line in (ROOT / ".ci" / "run").read_text().splitlines()]
    assert main_job in ci and tests in ci
    assert ci.index(main_job) < ci.index(tests)
