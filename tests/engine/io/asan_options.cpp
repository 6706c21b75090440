// Defaults for test_io_asan: memory errors abort the test; leak checking is off because
// LeakSanitizer cannot run where ptrace is blocked (e.g. default Docker), which would fail the
// build step that lists the tests.
extern "C" const char* __asan_default_options() { return "detect_leaks=0:abort_on_error=0"; }
