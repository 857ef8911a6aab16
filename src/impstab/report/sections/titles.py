"""The title of every section, in one place (a failed section is shown under it too)."""

#: section name -> title
TITLES = {
    "summary": "Model", "static": "Static deflection and mount loads", "modes": "Modes and decoupling",
    "stability": "Critical thrust and margin", "locus": "Eigenvalue loci",
    "simulation": "Time histories below, at and above the critical thrust", "isolation": "Vibration isolation",
    "postcritical": "Post-critical behaviour", "study": "Design study", "status": "Designs by status",
    "maps": "Stability maps", "best": "Best designs", "statistics": "Uncertainty statistics",
}
