"""What only the workflow's rules and scripts use: their logs, the modules a detect job
depends on, and the screenshots of the viewer and the report."""
