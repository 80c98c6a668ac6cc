"""Reports: plots and tables built from stored runs (matplotlib, headless)."""
