//! Case files: the TOML schema, loading with located errors, and validation.
