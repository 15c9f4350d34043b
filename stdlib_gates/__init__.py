"""The standard gate library of mlc, as data (one YAML file per gate)."""
