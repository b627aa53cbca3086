# The two commands of the README: `make demo` and `make test`. Both install what is missing
# (scripts/setup.sh), configure and build, then run.
BUILD ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
STRATA := $(BUILD)/app/strata

.PHONY: demo test setup build clean

demo: build
	$(STRATA) render -o demo.png

test: build
	cd $(BUILD) && ctest --output-on-failure

setup:
	scripts/setup.sh

build: setup
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE)
	cmake --build $(BUILD) -j $(JOBS)

clean:
	rm -rf $(BUILD)
