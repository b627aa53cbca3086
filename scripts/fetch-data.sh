#!/usr/bin/env bash
# Downloads the real data strata's demo and tests use, from Debian's archive, into the git-ignored
# assets/cache (nothing is installed system-wide): `apt-get download` fetches the .deb (apt checks
# it against the archive's signed index), `dpkg -x` unpacks it, and every file we use is checked
# against the SHA-256 pinned here (a .gz unpacked to a name without .gz is checked unpacked).
# Idempotent: files already in place and verified are kept.
#   mricron-data:   ch2.nii.gz (Colin27 T1 head MRI), aal.nii.gz + aal.nii.txt (116 AAL regions)
#   python3-pydicom: its DICOM test series dicomdirtests/98892001/CT5N (5 CT slices) and
#                    CT_small.dcm (one 128x128 CT slice), MR_small.dcm and MR_small_implicit.dcm
#                    (one MR slice, explicit and implicit VR little endian)
#   python3-nibabel: philips_mprage.dcm (an enhanced multi-frame MR: 176 frames of 256x256 in one
#                    file; its pixels are zeros), example4d.nii.gz (4-D NIfTI, 2 frames),
#                    nicom's 0.dcm (a Siemens diffusion mosaic: slices tiled in one image) and
#                    test.mgz (FreeSurfer MGH, gzipped: 3x4x5, 2 float frames, axes not of unit length)
#   assimp-testmodels: invalid/OutOfMemory.off (309 bytes whose header claims 3.5 million vertices:
#                    Assimp runs for minutes and takes gigabytes; the parser limits' test)
set -euo pipefail
cd "$(dirname "$0")/.."
cache=assets/cache
mkdir -p "$cache"

# package  file-inside-the-package  destination  sha256
files=(
  "mricron-data usr/share/mricron/templates/ch2.nii.gz mricron/ch2.nii.gz a009051127f64dc3dd554d5f5b589870ea72106d9642c21b4e7093e478cfc309"
  "mricron-data usr/share/mricron/templates/aal.nii.gz mricron/aal.nii.gz b512dcd3f36b77f56be7a9a038134096e66314b7e8c31d25875b96bcf6991454"
  "mricron-data usr/share/mricron/templates/aal.nii.txt mricron/aal.nii.txt 1788d6556a9ec056de9867b2382cf1ce1b51b87ae4cfd9cd25de48ae4dde709e"
)
pydicom=usr/lib/python3/dist-packages/pydicom/data/test_files
ct5n=$pydicom/dicomdirtests/98892001/CT5N
files+=(
  "python3-pydicom $ct5n/2062 dicom/CT5N/2062 27f8126485634a817f0941cc727094e8cfacb18341fbc317d175ff373804118b"
  "python3-pydicom $ct5n/2392 dicom/CT5N/2392 02b0af20eeae95f6d42554c53a630babaa5ed2519657208137d3c7418b6acb81"
  "python3-pydicom $ct5n/2693 dicom/CT5N/2693 6020fdffd513017e7b2d5dc52435b2bbf27209aabee183a30207a149dccecb2e"
  "python3-pydicom $ct5n/3023 dicom/CT5N/3023 4f7f4f2b3c79acdd5e0fc23fdd9f6bae6e6da9dccfadd1f9147b7bff53756653"
  "python3-pydicom $ct5n/3353 dicom/CT5N/3353 5eaa662118b8d87601a14231893cb7ecf1737a434c95120cfb4076cfce667b18"
  "python3-pydicom $pydicom/CT_small.dcm dicom/CT_small.dcm 3dd31e5cc835b3f2cdd46c9da1982f59251e78518fefa8163d914631c66437d6"
  "python3-pydicom $pydicom/MR_small.dcm dicom/MR_small.dcm 3f27d1c22f1a66e80d7bb7c911e8610fd0bb70325a76746a7adb1c0ddefcf2bb"
  "python3-pydicom $pydicom/MR_small_implicit.dcm dicom/MR_small_implicit.dcm 6077442c42a56fc7fcc7db8411a657dded9fc109e6d3275765c4de358292b299"
)
nibabel=usr/lib/python3/dist-packages/nibabel
files+=(
  "python3-nibabel $nibabel/nicom/tests/data/philips_mprage.dcm.gz dicom/philips_mprage.dcm 00058b3a5141b839493c21393c317e1cfe12ca912be8edf2f856ad3ea69fb6e3"
  "python3-nibabel $nibabel/tests/data/example4d.nii.gz nibabel/example4d.nii.gz 42097dfbab9d2a036b41ae5c97a359591cf2cf5c3f8dc6ca6455c0b8a7f22696"
  "python3-nibabel $nibabel/nicom/tests/data/0.dcm dicom/siemens_mosaic.dcm 7045df97f3f8300f3af2f5ef4006b77b8c3c1181b5668d5f9a4783d2375c6dbb"
  "python3-nibabel $nibabel/tests/data/test.mgz nibabel/test.mgz ee0d09022fa30dca0c16959a769893141122fe8c04b19708e2264576d2b7a6e9"
)
files+=(
  "assimp-testmodels usr/share/assimp/models/invalid/OutOfMemory.off assimp/OutOfMemory.off 4e337750dcd6b28e6c68392126a93d5756ef0f0d4f7d69c3c1c6ec413aefef7d"
)

verified() { [[ -f $1 ]] && echo "$2  $1" | sha256sum --check --status; }

unpacked=()
for entry in "${files[@]}"; do
  read -r package inside dest sum <<<"$entry"
  dest=$cache/$dest
  verified "$dest" "$sum" && continue
  if [[ ! " ${unpacked[*]} " == *" $package "* ]]; then
    echo "fetch-data: downloading $package from Debian's archive"
    rm -rf "$cache/deb-$package" && mkdir -p "$cache/deb-$package"
    (cd "$cache/deb-$package" && apt-get download "$package" >/dev/null 2>&1) || {
      # apt's lists may be missing on a fresh machine
      apt-get update -q >/dev/null && (cd "$cache/deb-$package" && apt-get download "$package" >/dev/null)
    }
    dpkg -x "$cache"/deb-"$package"/*.deb "$cache/deb-$package/root"
    unpacked+=("$package")
  fi
  mkdir -p "$(dirname "$dest")"
  if [[ $inside == *.gz && $dest != *.gz ]]; then
    gunzip -c "$cache/deb-$package/root/$inside" >"$dest"
  else
    cp "$cache/deb-$package/root/$inside" "$dest"
  fi
  if ! verified "$dest" "$sum"; then
    echo "fetch-data: $dest: SHA-256 does not match the pinned value (package $package changed?)" >&2
    rm -f "$dest"
    exit 1
  fi
done
rm -rf "$cache"/deb-*

# The demo segmentation (README, docs/scene-format.md): AAL's regions grouped into 27 structures,
# a multi-label NIfTI with its names in the header, as TotalSegmentator writes one.
demo_seg=$cache/demo/head-regions.nii.gz
if [[ ! -f $demo_seg || $demo_seg -ot scripts/make-demo-segmentation.py ]]; then
  mkdir -p "$cache/demo"
  python3 scripts/make-demo-segmentation.py "$cache/mricron/aal.nii.gz" \
    "$cache/mricron/aal.nii.txt" "$demo_seg.part"
  mv "$demo_seg.part" "$demo_seg"
fi
