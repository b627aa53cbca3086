#!/usr/bin/env python3
"""Writes the demo segmentation: the AAL atlas's 116 regions (mricron-data's aal.nii.gz and
aal.nii.txt) grouped into 27 structures (lobes, deep nuclei, cerebellum; left and right), as a
multi-label NIfTI-1 whose header extension holds its names and colours in the form
TotalSegmentator's --ml output has (code 0, an XML LabelTable). Only Python's standard library:
the NIfTI-1 header is copied, vox_offset moved past the extension, the voxels regrouped.

    scripts/make-demo-segmentation.py AAL.nii.gz AAL.txt OUT.nii.gz
"""
import colorsys
import gzip
import struct
import sys

# Structure -> the AAL names (without _L/_R) it gathers; every one is split left and right but
# the vermis, which lies on the midline.
GROUPS = [
    ("frontal_lobe", ["Precentral", "Frontal_Sup", "Frontal_Sup_Orb", "Frontal_Mid",
                      "Frontal_Mid_Orb", "Frontal_Inf_Oper", "Frontal_Inf_Tri", "Frontal_Inf_Orb",
                      "Rolandic_Oper", "Supp_Motor_Area", "Olfactory", "Frontal_Sup_Medial",
                      "Frontal_Med_Orb", "Rectus"]),
    ("parietal_lobe", ["Postcentral", "Parietal_Sup", "Parietal_Inf", "SupraMarginal", "Angular",
                       "Precuneus", "Paracentral_Lobule"]),
    ("temporal_lobe", ["Heschl", "Temporal_Sup", "Temporal_Pole_Sup", "Temporal_Mid",
                       "Temporal_Pole_Mid", "Temporal_Inf"]),
    ("occipital_lobe", ["Calcarine", "Cuneus", "Lingual", "Occipital_Sup", "Occipital_Mid",
                        "Occipital_Inf", "Fusiform"]),
    ("insula", ["Insula"]),
    ("cingulate_gyrus", ["Cingulum_Ant", "Cingulum_Mid", "Cingulum_Post"]),
    ("hippocampus", ["Hippocampus", "ParaHippocampal"]),
    ("amygdala", ["Amygdala"]),
    ("caudate", ["Caudate"]),
    ("putamen", ["Putamen"]),
    ("pallidum", ["Pallidum"]),
    ("thalamus", ["Thalamus"]),
    ("cerebellum", ["Cerebelum_Crus1", "Cerebelum_Crus2", "Cerebelum_3", "Cerebelum_4_5",
                    "Cerebelum_6", "Cerebelum_7b", "Cerebelum_8", "Cerebelum_9", "Cerebelum_10"]),
]


def structures():
    """[(name, [aal base names], side suffix or None)] in label order."""
    out = []
    for name, members in GROUPS:
        out.append((name + "_left", members, "_L"))
        out.append((name + "_right", members, "_R"))
    out.append(("vermis", ["Vermis_1_2", "Vermis_3", "Vermis_4_5", "Vermis_6", "Vermis_7",
                           "Vermis_8", "Vermis_9", "Vermis_10"], None))
    return out


def label_table(names):
    rows = []
    for key, name in enumerate(names, start=1):
        r, g, b = colorsys.hsv_to_rgb((key * 0.618034) % 1.0, 0.65, 0.95)
        rows.append(f'<Label Key="{key}" Red="{r:.3f}" Green="{g:.3f}" Blue="{b:.3f}" '
                    f'Alpha="1"><![CDATA[{name}]]></Label>')
    return ('<?xml version="1.0" encoding="UTF-8"?>\n<CaretExtension>\n<VolumeInformation '
            'Index="0">\n<LabelTable>\n' + "\n".join(rows) + '\n</LabelTable>\n<VolumeType>'
            '<![CDATA[Label]]></VolumeType>\n</VolumeInformation>\n</CaretExtension>\n')


def main(atlas, names_file, out):
    data = gzip.open(atlas, "rb").read()
    if struct.unpack("<i", data[0:4])[0] != 348:
        sys.exit(f"{atlas}: not a little-endian NIfTI-1 file")
    datatype, bitpix = struct.unpack("<hh", data[70:74])
    if (datatype, bitpix) != (2, 8):
        sys.exit(f"{atlas}: expected uint8 voxels (datatype 2), got {datatype}")
    vox_offset = int(struct.unpack("<f", data[108:112])[0])
    aal = {}
    for line in open(names_file, encoding="utf-8"):
        fields = line.split()
        if len(fields) >= 2:
            aal[fields[1]] = int(fields[0])
    lookup = bytearray(256)
    chosen = structures()
    for key, (_, members, side) in enumerate(chosen, start=1):
        for member in members:
            lookup[aal[member + (side or "")]] = key
    voxels = data[vox_offset:].translate(bytes(lookup))

    xml = label_table([name for name, _, _ in chosen]).encode("utf-8")
    size = (8 + len(xml) + 15) // 16 * 16
    extension = struct.pack("<ii", size, 0) + xml.ljust(size - 8, b"\0")
    header = bytearray(data[:348])
    offset = 352 + len(extension)
    header[108:112] = struct.pack("<f", float(offset))
    header[148:228] = b"strata demo: AAL regions grouped".ljust(80, b"\0")
    with gzip.GzipFile(out, "wb", mtime=0) as f:
        f.write(bytes(header) + bytes([1, 0, 0, 0]) + extension + voxels)


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
