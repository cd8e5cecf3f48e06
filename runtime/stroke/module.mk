# runtime/stroke: prescribed strokes (scene table [stroke], (3.21) only) and `swim run` on them
# (cli/stroke_run.c, listed here so that the stroke path is one module).
RUNTIME_SRCS += runtime/stroke/stroke.c runtime/cli/stroke_run.c
