"""monitor.log."""
