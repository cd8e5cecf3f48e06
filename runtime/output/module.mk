# runtime/output: where a run's rows and results go -- its output folder (a sink of driver/run.h).
RUNTIME_SRCS += runtime/output/folder.c runtime/output/job.c
