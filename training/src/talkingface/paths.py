"""Where the repository's shared folders are, found from this file, never from the working directory."""
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[3]
MODELS_DIR = REPO_ROOT / "models"
TEMPLATE_DIR = MODELS_DIR / "template"
