# runtime/stroke: prescribed strokes (scene table [stroke], (3.21) only) and `swim run` on them
# (the run of a stroke scene is driver/stroke_run.c).
RUNTIME_SRCS += runtime/stroke/stroke.c
