#!/usr/bin/env bash
# The GPU check of a session that is lent an NVIDIA machine (see
# benchmarks/README.md, "On a GPU"): pyoa's conformance, block-rule, request,
# sampler and render suites with the OpenCL device set to the NVIDIA GPU, then
# the generate benchmark's Bose cases there. The wheels pyoa needs beyond that
# machine's image are carried in .whl/ (pyopencl and its helpers, embreex,
# OpenImageIO, trimesh, dask/distributed); logs go to $OUT.
set -u
OUT=${OUT:-/tmp/out}
mkdir -p "$OUT"
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
    --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=/tmp/site:$PWD PYTHONUNBUFFERED=1
# The source tree maps kernels/ and scenes/ into the package only when
# installed (setup.cfg package_dir); this copy is run from the tree.
ln -sfn ../kernels pyoa/kernels && ln -sfn ../scenes pyoa/scenes
# pip's pyopencl carries its own ICD loader; point it at NVIDIA's driver (the
# image's own vendors folder may list only PoCL).
lib=$(find /usr/local/nvidia /usr/lib /usr/lib64 -name 'libnvidia-opencl.so*' 2>/dev/null | head -1)
echo "NVIDIA OpenCL library: ${lib:-none found}"; [ -n "$lib" ] || exit 1
if [ -n "$lib" ]; then
    mkdir -p /tmp/vendors && echo "$lib" > /tmp/vendors/nvidia.icd
    export OCL_ICD_VENDORS=/tmp/vendors
fi
nvidia-smi -L
python3 -c 'import numpy, numba, pyopencl as cl; print("numpy", numpy.__version__, "numba", numba.__version__);
[print(p.name, p.version, "|", d.name, d.driver_version) for p in cl.get_platforms() for d in p.get_devices()]' || exit 1
export PYOA_OPENCL_DEVICE=nvidia PYOA_REQUIRE_OPENCL=1 PYOA_TEST_DEVICES=all
python3 -m pyoa backends 2>&1 | tee "$OUT/backends.txt"
TESTS=${TESTS:-"tests/_opencl tests/test_conformance.py tests/test_baselines_conformance.py
    tests/test_block_pairs.py tests/test_spec_blocks.py tests/test_catalogue.py tests/test_request.py
    tests/test_samplers.py tests/test_faure.py tests/test_to_dask.py tests/render"}
# shellcheck disable=SC2086
timeout "${TEST_LIMIT:-330}" python3 -m pytest -q -n 14 -p no:cacheprovider $TESTS 2>&1 \
    | tee "$OUT/conformance-gpu.log" | tail -40
echo "pytest exit: ${PIPESTATUS[0]}"
# The portable headers in a CUDA program (benchmarks/cuda/values.cu, built with nvcc here, or the
# binary $CUDA_BINARY built elsewhere for this GPU and carried), every catalogue sampler bit for bit
# against NumPy, and its rate (benchmarks/cuda_check.py; CUDA_LIMIT=0 skips it). Its exit status: 2
# no usable GPU, 3 no nvcc.
nvcc_bin=$(command -v nvcc || { [ -x "${CUDA_HOME:-/usr/local/cuda}/bin/nvcc" ] && echo "${CUDA_HOME:-/usr/local/cuda}/bin/nvcc"; })
if [ -n "${CUDA_BINARY:-}" ]; then
    cuda_args=(--binary "$CUDA_BINARY")
elif [ -n "$nvcc_bin" ]; then
    cuda_args=(--nvcc "$nvcc_bin")
else
    cuda_args=()
fi
if [ "${CUDA_LIMIT:-120}" = 0 ]; then
    echo "CUDA check skipped (CUDA_LIMIT=0)"
elif [ ${#cuda_args[@]} = 0 ]; then
    echo "CUDA check skipped: nvcc not found (PATH, ${CUDA_HOME:-/usr/local/cuda}/bin) and no CUDA_BINARY; benchmarks/cuda_check.py needs the CUDA toolkit or a prebuilt values.cu"
else
    echo "CUDA check: ${cuda_args[*]}"
    timeout "${CUDA_LIMIT:-120}" python3 benchmarks/cuda_check.py "${cuda_args[@]}" --out "$OUT" 2>&1 \
        | tee "$OUT/cuda-check.log" | tail -25
    echo "cuda_check exit: ${PIPESTATUS[0]}"
fi
[ "${BENCH_LIMIT:-90}" = 0 ] || timeout "${BENCH_LIMIT:-90}" python3 benchmarks/bench_generate.py --backends opencl --no-peers \
    --cases bose-cmj-121x10,bose-cmj-121x12,bose-cmj-121x36,bush-cmj-125x10 --repeats 9 \
    --out "$OUT/generate-gpu.json" 2>&1 | tail -20
ls -la "$OUT"
