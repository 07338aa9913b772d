"""Reports and plots of simulation results."""
