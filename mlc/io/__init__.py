"""What several stages share: file formats (YAML with source lines, schema validation, atomic
writes), progress lines, the cores this process may use."""
