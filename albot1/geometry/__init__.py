"""Pure geometry: SE(2) poses and line segments (numpy only, no I/O)."""
