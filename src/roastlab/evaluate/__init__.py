"""roastlab.evaluate"""
