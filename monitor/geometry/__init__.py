"""monitor.geometry."""
