# Run-time code generation: generator process, compiler, kernel cache (runtime/codegen/codegen.h).
RUNTIME_SRCS += runtime/codegen/codegen.c runtime/codegen/structure.c
$(BUILD)/runtime/codegen/codegen.o: CPPFLAGS += -DSWIM_CC='"$(CC)"' -DSWIM_KERNEL_CFLAGS='"$(KERNEL_OPT)"'
BENCH_SRCS   += tests/bench/bench_cache.c
BENCH_SRCS   += tests/bench/bench_kernel_flags.c
$(BUILD)/tests/bench/bench_kernel_flags.o: CPPFLAGS += -DSWIM_CC='"$(CC)"' -DSWIM_KERNEL_CFLAGS='"$(KERNEL_OPT)"'
