"""monitor.motion."""
