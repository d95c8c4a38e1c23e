"""surrogate: the runtime rebound sampler (reads tables made by tablegen; never imports it)."""
