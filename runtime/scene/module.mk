# runtime/scene: scene-file reading (TOML subset, see runtime/scene/toml.h).
# Fuzzing (clang/libFuzzer, not part of `make test`): bash tests/fuzz/run_fuzz.sh [SECONDS]
RUNTIME_SRCS += runtime/scene/toml.c
# Scenes (swim_scene_load) and forcing laws (swim_expr).
RUNTIME_SRCS += runtime/scene/scene.c runtime/scene/keys.c runtime/scene/expr.c
# The scene as run: overrides written into the scene file's text (swim_scene_resolve).
RUNTIME_SRCS += runtime/scene/resolve.c
# Energy laws U(I1, J) of [elastic] energy: reading and checking them (swim_material_*).
RUNTIME_SRCS += runtime/scene/material.c
