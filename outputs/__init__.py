"""What a run writes for its readers: tables (CSV, Markdown, LaTeX), figures, rerun
recordings, Parquet copies, provenance and the paper's sources."""
