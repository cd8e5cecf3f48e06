# runtime/export: swim export, one scene's self-contained source tree (docs/export.md). The tree is
# built with the compiler and flags of this build, baked into export.o here. simulate.c, kernels.c
# and no_cvode.c are not part of bin/swim: they are copied into the tree.
RUNTIME_SRCS += runtime/export/export.c
$(BUILD)/runtime/export/export.o: CPPFLAGS += -DSWIM_EXPORT_CC='"$(CC)"' \
  -DSWIM_EXPORT_CFLAGS='"$(strip $(filter-out -MMD -MP,$(CFLAGS)))"' -DSWIM_EXPORT_KERNEL_OPT='"$(KERNEL_OPT)"'
