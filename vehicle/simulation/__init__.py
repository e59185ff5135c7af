"""Running the car: bushing coupling, the compiled step loop, the K&C rig, scenario runs, K&C triangles."""
