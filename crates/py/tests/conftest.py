"""What the Python tests share: the repository's paths."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
MODELS = ROOT / "models"
# `make test` builds the CLI before it runs these tests.
DEXCUBE = ROOT / "target" / "release" / "dexcube"
