"""Design optimisation: population search, polish, OPT files."""
