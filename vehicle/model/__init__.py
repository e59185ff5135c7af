"""The vehicle model: the vehicle file and its values set by place, its MuJoCo model (MjSpec), rigid kinematics, static preloads and the steering axis."""
