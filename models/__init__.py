"""MJCF scenes shipped with monitor (package data; see monitor._paths.models_dir)."""
