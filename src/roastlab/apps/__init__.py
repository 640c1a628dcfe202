"""roastlab.apps"""
