"""Controller variants side by side (aic_compare.py): named variants (variants), their runs, table,
CSV and JSON (compare), figures (compare_plot); run_variant, the Python API of one headless run of
a configuration with overrides on a plant variant and profile."""
from .compare import run_variant  # noqa: F401
