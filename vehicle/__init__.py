"""The MuJoCo car and how it is mounted: its model, what it is made to do, and its simulation."""
