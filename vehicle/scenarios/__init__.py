"""What the car is made to do on the rig and on the road: scenario files, input channels, road logs, case schedules, K&C tests, the rig's own mechanics."""
