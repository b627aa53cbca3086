# Shortcuts for the scripts the README names.
.PHONY: demo test build clean
demo:
	scripts/demo
test:
	scripts/test
build:
	scripts/build.sh
clean:
	rm -rf build
