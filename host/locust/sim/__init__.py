"""Four-bar solver, MuJoCo model builder, audited hop rollout."""
