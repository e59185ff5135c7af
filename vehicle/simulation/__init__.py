"""Running the car: bushing coupling, the compiled step loops and measurement, the K&C rig, the road and its driver, scenario runs, K&C triangles, unconverged bushing steps."""
