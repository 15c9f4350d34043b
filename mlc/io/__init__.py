"""File formats shared by several stages: YAML with source lines, schema validation."""
