"""Built-in material presets: one YAML file per preset, the file stem is its name."""
