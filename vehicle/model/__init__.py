"""The vehicle model: the vehicle file, its MuJoCo model (MjSpec), rigid kinematics and static preloads."""
