"""monitor.commands."""
