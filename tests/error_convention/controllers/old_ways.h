// A fixture for test_error_convention.sh --self-test. Never compiled.
const char* tx_fixture_def_check(const void* def);
