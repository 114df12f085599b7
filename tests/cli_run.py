"""What the command-line tests share: the paper's scene as a mapping, its rigid-walker part
(no contact sections), and a run of the CLI in-process."""

from __future__ import annotations

from pathlib import Path

import yaml
from typer.testing import CliRunner

from walkerlab.cli import app

ROOT = Path(__file__).resolve().parents[1]
#: configs/paper.yaml as a mapping
PAPER = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
#: its rigid walker alone: the sections the ideal stages read
IDEAL = {k: v for k, v in PAPER.items() if k in ("walker", "slope", "solver", "fixedpoint",
                                                  "simulate")}


def run_cli(*args, env=None) -> tuple[int, str, str]:
    """``walkerlab ARGS`` in-process: (exit code, stderr stripped, stdout)."""
    r = CliRunner().invoke(app, [str(a) for a in args], env=env)
    return r.exit_code, r.stderr.strip(), r.stdout
