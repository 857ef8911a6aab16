"""Text and HTML views of models and results for the terminal and notebooks."""

def locus_text(r):
    return f"LocusResult({r.model_name!r})"

def locus_html(r):
    return "<p>locus</p>"
