"""Subcommands of the `quadgcs` console script that need the bundled SITL in this process."""
