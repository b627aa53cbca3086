"""Writes a small DICOM Segmentation (BINARY) with pydicom, by PS3.3 A.51 and C.8.20, for
tests/dicom_seg_tests.cpp: 4 x 3 pixels, 2 slices 3 mm apart, two segments (the second named only
by its property type's code meaning), three frames whose bits run on across byte boundaries.

Usage: dicom_seg_pydicom.py OUTPUT.dcm
"""
import sys

import numpy as np
from pydicom.dataset import Dataset, FileDataset, FileMetaDataset
from pydicom.pixel_data_handlers.numpy_handler import pack_bits
from pydicom.sequence import Sequence
from pydicom.uid import ExplicitVRLittleEndian, generate_uid

SEGMENTATION_STORAGE = "1.2.840.10008.5.1.4.1.1.66.4"


def code(value, scheme, meaning):
    item = Dataset()
    item.CodeValue = value
    item.CodingSchemeDesignator = scheme
    item.CodeMeaning = meaning
    return item


def segment(number, label, meaning):
    item = Dataset()
    item.SegmentNumber = number
    if label:
        item.SegmentLabel = label
    item.SegmentAlgorithmType = "MANUAL"
    item.SegmentedPropertyCategoryCodeSequence = Sequence([code("123037004", "SCT", "Anatomical Structure")])
    item.SegmentedPropertyTypeCodeSequence = Sequence([code("64033007", "SCT", meaning)])
    return item


def frame(segment_number, z):
    position = Dataset()
    position.ImagePositionPatient = [0.0, 0.0, z]
    identification = Dataset()
    identification.ReferencedSegmentNumber = segment_number
    item = Dataset()
    item.PlanePositionSequence = Sequence([position])
    item.SegmentIdentificationSequence = Sequence([identification])
    return item


def main(output):
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = SEGMENTATION_STORAGE
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = FileDataset(output, {}, file_meta=meta, preamble=b"\0" * 128)
    ds.SOPClassUID = SEGMENTATION_STORAGE
    ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    ds.Modality = "SEG"
    ds.SeriesInstanceUID = generate_uid()
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.Rows, ds.Columns = 3, 4
    ds.BitsAllocated = ds.BitsStored = 1
    ds.HighBit = 0
    ds.PixelRepresentation = 0
    ds.SegmentationType = "BINARY"
    ds.SegmentSequence = Sequence([segment(1, "Left kidney", "Kidney"), segment(2, "", "Spleen")])

    orientation = Dataset()
    orientation.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
    measures = Dataset()
    measures.PixelSpacing = [0.8, 0.8]
    measures.SliceThickness = 3.0
    shared = Dataset()
    shared.PlaneOrientationSequence = Sequence([orientation])
    shared.PixelMeasuresSequence = Sequence([measures])
    ds.SharedFunctionalGroupsSequence = Sequence([shared])

    kidney = np.zeros((3, 4), np.uint8)
    kidney.flat[0:5] = 1
    spleen = np.zeros((3, 4), np.uint8)
    spleen.flat[11] = 1
    frames = [(1, 0.0, kidney), (2, 3.0, spleen), (2, 0.0, spleen)]
    ds.PerFrameFunctionalGroupsSequence = Sequence([frame(n, z) for n, z, _ in frames])
    ds.NumberOfFrames = len(frames)
    ds.PixelData = pack_bits(np.stack([mask for _, _, mask in frames]))
    ds.is_little_endian = True
    ds.is_implicit_VR = False
    ds.save_as(output, write_like_original=False)


if __name__ == "__main__":
    main(sys.argv[1])
