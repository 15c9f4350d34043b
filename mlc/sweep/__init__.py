"""Parameter sweeps of Brownian-dynamics runs on Dask (``mlc sweep``; docs/reproduction.md)."""
