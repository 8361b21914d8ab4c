"""Time integration of ``M p'' + C p' + K p = F(t)``: analytic (modal) and numerical."""
