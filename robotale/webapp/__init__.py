"""The dashboard: a Flask application factory with one blueprint per page.

``create_app()`` builds it; ``robotale serve`` runs it on http://127.0.0.1:5000. Pages: Logs
(upload and ingest, list, delete), Discover (DFG and aggregated EKG), Perspectives, Model
(the BPMN collaboration coloured by the log) and a read-only Cypher console. Every JavaScript
library is served by the app itself (``static/vendor``), so it works offline.
"""

from robotale.webapp.app import create_app

__all__ = ["create_app"]
