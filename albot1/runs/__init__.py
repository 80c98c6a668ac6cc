"""Running a method on a sequence: the mapper protocol, the result type, the
method registry, the timed runner and the run-folder contract."""
