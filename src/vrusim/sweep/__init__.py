"""Parameter sweeps: specs, execution, the Parquet results store and its analysis."""
