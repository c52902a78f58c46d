"""Subcommands of the `quadgcs` console script, one module each (see `gcs.cli`)."""
