# runtime/driver: one run of a scene, whatever command asks for it (run, sweep members, optimize,
# floquet, sensitivities): the integration policy, its checks, events and the run's result.
RUNTIME_SRCS += runtime/driver/columns.c runtime/driver/events.c runtime/driver/watch.c runtime/driver/kinds.c runtime/driver/run.c runtime/driver/stroke_run.c runtime/driver/summary.c runtime/driver/analyses.c runtime/driver/flow.c
# the one summary reader (summary.json read back: members.csv, sweep resume); jansson
RUNTIME_SRCS += runtime/driver/summary_read.c
