"""Enhancement: spatial, communication, battery and performance perspectives as tables and
plotly figures."""
