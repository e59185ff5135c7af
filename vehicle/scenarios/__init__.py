"""What the car is made to do on the rig and on the road: scenario files, input channels, case schedules, K&C tests."""
