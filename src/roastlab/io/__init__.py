"""roastlab.io"""
