"""Where runs execute: a Dask cluster started on this machine (default), an existing one by its scheduler's address, or this process."""
