"""roastlab.workflows"""
