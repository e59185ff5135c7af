"""What people look at: PNG plots, the Rerun replay, text tables and the diagnosis reports."""
