# Independent reference implementation used by the tests (tests/reference/ref_model.c).
TEST_LIB_SRCS += tests/reference/ref_model.c tests/reference/ref_rhs.c
