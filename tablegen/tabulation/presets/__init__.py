"""Embedded build-configuration presets (TOML): default, production, paper."""
