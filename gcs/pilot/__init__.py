"""What the pilot asks for (intents) and what the pilot is shown (the teleop view): shared by
every way of flying by hand (the TUI, the gamepad), which must not import each other."""
