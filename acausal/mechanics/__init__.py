"""The mechanical component library. Sign convention: :mod:`acausal.connectors`."""
