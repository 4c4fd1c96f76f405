"""Discovery: directly-follows graphs, aggregated EKG models and conformance."""
