"""Drawing of result objects with matplotlib; imported lazily, nothing configured at import."""
