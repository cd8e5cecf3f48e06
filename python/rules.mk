# python/: the package `swim` (ctypes over libswim, docs/python.md). No build step: `make install`
# copies python/swim/*.py into PREFIX/lib/python3/dist-packages/swim, where the package finds
# PREFIX/lib/libswim.so.MAJOR from its own location (Debian's python3 has
# /usr/local/lib/python3/dist-packages on its path; another PREFIX needs PYTHONPATH).
# `make uninstall` removes those files and the bytecode Python wrote beside them, and the folders
# install made (tools/install_manifest.sh) left empty. PREFIX may hold spaces and quotes: it reaches the shell through the environment, as
# in runtime/lib/rules.mk.
PY_FILES   := $(sort $(wildcard python/swim/*.py))
PY_PKG_DIR := lib/python3/dist-packages/swim

.PHONY: install-python uninstall-python
install: install-python
install-python: export SWIM_INSTALL_DEST := $(DESTDIR)$(PREFIX)
install-python: install-lib | install-begin
	@case "$$SWIM_INSTALL_DEST" in /*) ;; *) echo "make install: PREFIX='$$SWIM_INSTALL_DEST' is not an absolute path" >&2; exit 2 ;; esac
	install -d "$$SWIM_INSTALL_DEST/$(PY_PKG_DIR)"
	install -m 644 $(PY_FILES) "$$SWIM_INSTALL_DEST/$(PY_PKG_DIR)/"
	@$(INSTALL_RECORD)

uninstall: uninstall-python
uninstall-python: export SWIM_INSTALL_DEST := $(DESTDIR)$(PREFIX)
uninstall-python:
	cd "$$SWIM_INSTALL_DEST/$(PY_PKG_DIR)" 2>/dev/null && rm -f $(notdir $(PY_FILES)) && rm -rf __pycache__; true
	bash tools/install_manifest.sh prune

# the loop of swim.run against swim sweep (tests/bench/bench_python_loop.py) needs the library
bench: $(LIB_SO)
