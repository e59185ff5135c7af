"""What the car is made to do on the rig: scenario files, input channels, case schedules, K&C tests."""
