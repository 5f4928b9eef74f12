# Thin wrappers over scripts/ (the README's commands).
.PHONY: setup run test test-asan bench format viewer
setup:
	scripts/setup.sh
run:
	scripts/run.sh
test:
	scripts/test.sh
test-asan:
	scripts/test.sh --sanitize
bench: setup
	build/bench/atmos_bench
viewer: setup
	build/atmos viewer -o out/viewer
format:
	clang-format -i $$(git ls-files '*.h' '*.cpp' '*.cu')
