"""Human-readable summaries and the HTML/Markdown report, built from artifacts only."""
