// A shared library that is not an estimator plugin: it has no entry point.
extern "C" __attribute__((visibility("default"))) int some_other_library_function() { return 42; }
