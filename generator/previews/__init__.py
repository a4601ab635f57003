"""Pictures for people: image previews (RGB | labels | depth), LiDAR bird's-eye views, contact
sheets and the town map. Pillow and numpy only; nothing here is read back by the tools.
"""
