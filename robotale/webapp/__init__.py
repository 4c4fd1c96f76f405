"""The dashboard: a Flask application factory with one blueprint per page."""
