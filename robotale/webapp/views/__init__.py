"""One blueprint per page; pages are HTML, their data comes from JSON endpoints under /api/."""
