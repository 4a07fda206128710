// Run outputs (history CSV, summary JSON, run folder): see output.hpp.
