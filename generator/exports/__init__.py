"""Exports of a generated dataset into the layouts other ecosystems read (nuScenes, COCO).

Each module reads the dataset (scans, labels, images, the box records rebuilt from its spec), builds
everything in a stage inside the output folder and moves it in at the end, so a failed export leaves
nothing behind. The record layouts themselves live in :mod:`generator.formats`.
"""
