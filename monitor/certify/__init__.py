"""monitor.certify."""
