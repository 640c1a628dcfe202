"""roastlab.model"""
