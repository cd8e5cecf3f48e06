# runtime/problem: a problem built once -- a scene (file or text) with its overrides, validated,
# its kernels and its dynamics; run-time keys set in place (problem.h). Below the driver, above
# scene/, codegen/ and model/.
RUNTIME_SRCS += runtime/problem/problem.c
